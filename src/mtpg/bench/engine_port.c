/* The engine benchmark's workload in hand-written C: the yardstick of `mtpg bench engine --c`.
 *
 * The same work as mtpg.engine.episode_kernels.run_jobs_queue on one thread: every job (graph x
 * CartPole episode) resets the task, then decides and steps until the episode ends; a
 * decision traverses the graph from the job's root, running each visited team's programs
 * on a workspace of private registers, constants, the observation and the memory banks,
 * and follows the first highest eligible bid. Memory banks are zeroed lazily, once per
 * job, as in the engine. Same arrays, same operation order, the same C library functions:
 * the results equal the engine's bit for bit (mtpg.bench.c_port checks every job).
 *
 * Written as a careful C programmer would, doing no work the engine avoids: the protection
 * limits are compile-time constants (-DMTPG_BIG=... etc., exact hexadecimal literals given
 * by mtpg.bench.c_port.build), and the eight private registers of the common layout are
 * cleared by eight stores, not a memset call per program run.
 *
 * Usage: engine_port IN OUT [PASSES]. IN holds the compiled graph and the episodes (layout
 * in mtpg.bench.c_port); OUT receives per-job returns, steps, teams and instructions of the
 * last pass. The job loop runs PASSES times (default 2); only the last is timed, so, like
 * the engine, it runs warm (code, input and heap pages touched). A timed pass allocates its
 * workspace, stamps and outputs, as the engine's run_jobs does inside its timed call.
 * Prints the process CPU seconds of the timed pass.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { N_HEADER = 13, STATE_SIZE = 6, PREV_FORCE = 4, STEP = 5 };

/* CartPole parameter columns (mtpg.envs.dynamics.cartpole). */
enum { MAX_STEPS, FORCE, TAU, GRAVITY, MASSCART, MASSPOLE, LENGTH, X_THRESHOLD, THETA_THRESHOLD };

#if !defined(MTPG_BIG) || !defined(MTPG_DIV_EPS) || !defined(MTPG_LOG_BIG) || !defined(MTPG_LOG_TINY)
#error "build with -DMTPG_BIG=... -DMTPG_DIV_EPS=... -DMTPG_LOG_BIG=... -DMTPG_LOG_TINY=..."
#endif
static const double BIG = MTPG_BIG, DIV_EPS = MTPG_DIV_EPS, LOG_BIG = MTPG_LOG_BIG,
                    LOG_TINY = MTPG_LOG_TINY;

static double clamp(double v)
{
    if (v > BIG)
        return BIG;
    if (v < -BIG)
        return -BIG;
    return v;
}

/* The protected operations of Table 2 and the engine's copy (mtpg.engine.ops.apply_op). */
static double apply_op(uint32_t op, double d, double a, double b)
{
    double v, x, e;
    switch (op) {
    case 0: v = a + b; break;
    case 1: v = a - b; break;
    case 2: v = a * b; break;
    case 3: v = fabs(b) < DIV_EPS ? a : a / b; break;
    case 4:
        x = fabs(a);
        if (x == 0.0) {
            v = 0.0;
        } else {
            e = b * log(x);
            if (e > LOG_BIG)
                v = BIG;
            else if (e < LOG_TINY)
                v = 0.0;
            else
                v = pow(x, b);
        }
        break;
    case 5: v = cos(b); break;
    case 6: v = b == 0.0 ? 0.0 : log(fabs(b)); break;
    case 7: v = b > LOG_BIG ? BIG : exp(b); break;
    case 8: v = sqrt(fabs(b)); break;
    case 9: v = sin(b); break;
    case 10: v = tanh(b); break;
    case 11: v = b * b; break;
    case 12: v = fabs(b); break;
    case 13: v = b * b * b; break;
    case 14: v = a < b ? -d : d; break;
    case 15: v = a > b ? -d : d; break;
    default: return b; /* OP_COPY of a folded constant (mtpg.engine.fold) */
    }
    return clamp(v);
}

typedef struct {
    const int64_t *team_offsets, *team_members, *prog_offsets, *prog_action, *prog_bank,
        *prog_count;
    const uint32_t *instrs;
    size_t R, M, base;
} Graph;

/* One decision from `root`; returns a_d and stores a_c. counts[0]: teams, counts[1]: instrs. */
static int decide(const Graph *g, int64_t root, double *W, int64_t *team_stamp, int64_t stamp,
                  int64_t *bank_stamp, int64_t episode, int64_t *counts, double *a_c)
{
    int64_t team = root;
    for (;;) {
        int64_t best_p = -1, act;
        double best = 0.0;
        team_stamp[team] = stamp;
        counts[0]++;
        for (int64_t k = g->team_offsets[team]; k < g->team_offsets[team + 1]; k++) {
            int64_t p = g->team_members[k];
            int64_t bank = g->prog_bank[p];
            if (bank_stamp[bank] != episode) {
                memset(W + g->base + (size_t)bank * g->M, 0, g->M * sizeof *W);
                bank_stamp[bank] = episode;
            }
            if (g->R == 8) { /* the common layout: eight plain stores, as in the engine */
                W[0] = W[1] = W[2] = W[3] = W[4] = W[5] = W[6] = W[7] = 0.0;
            } else {
                for (size_t i = 0; i < g->R; i++)
                    W[i] = 0.0;
            }
            for (int64_t i = g->prog_offsets[p]; i < g->prog_offsets[p + 1]; i++) {
                const uint32_t *in = g->instrs + 4 * i;
                W[in[1]] = apply_op(in[0], W[in[1]], W[in[2]], W[in[3]]);
            }
            counts[1] += g->prog_count[p]; /* effective instructions before folding */
            act = g->prog_action[p];
            if ((act < 0 || team_stamp[act] != stamp) && (best_p < 0 || W[0] > best)) {
                best = W[0];
                best_p = p;
            }
        }
        act = g->prog_action[best_p];
        if (act < 0) {
            *a_c = W[g->base + (size_t)g->prog_bank[best_p] * g->M];
            return (int)(-1 - act);
        }
        team = act;
    }
}

static double clip_obs(double x)
{
    if (x != x)
        return 0.0;
    return x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x);
}

/* CartPole's step (mtpg.envs.dynamics.cartpole.step, Gymnasium's operation order). */
static int cartpole_step(const double *p, double *s, int a_d)
{
    double force = a_d == 0 ? p[FORCE] : (a_d == 2 ? -p[FORCE] : s[PREV_FORCE]);
    double x = s[0], x_dot = s[1], theta = s[2], theta_dot = s[3];
    double masspole = p[MASSPOLE], length = p[LENGTH];
    double total_mass = masspole + p[MASSCART];
    double polemass_length = masspole * length;
    double tau = p[TAU];
    double costheta = cos(theta), sintheta = sin(theta);
    double temp = (force + polemass_length * (theta_dot * theta_dot) * sintheta) / total_mass;
    double thetaacc = (p[GRAVITY] * sintheta - costheta * temp) /
                      (length * (4.0 / 3.0 - masspole * (costheta * costheta) / total_mass));
    double xacc = temp - polemass_length * thetaacc * costheta / total_mass;
    s[PREV_FORCE] = force;
    s[0] = x + tau * x_dot;
    s[1] = x_dot + tau * xacc;
    s[2] = theta + tau * theta_dot;
    s[3] = theta_dot + tau * thetaacc;
    return s[0] < -p[X_THRESHOLD] || s[0] > p[X_THRESHOLD] || s[2] < -p[THETA_THRESHOLD] ||
           s[2] > p[THETA_THRESHOLD];
}

static void *read_block(FILE *f, size_t n, size_t size)
{
    void *buf = malloc(n * size + 1);
    if (!buf || fread(buf, size, n, f) != n) {
        fprintf(stderr, "engine_port: truncated input\n");
        exit(3);
    }
    return buf;
}

typedef struct {
    double *returns;
    int64_t *counts; /* steps, teams, instructions per job */
} Outcome;

/* One pass over every job: allocates its buffers, plays every job, returns the outcomes. */
static Outcome play_all(const Graph *g, int64_t n_teams, int64_t n_banks, int64_t n_jobs,
                        const int64_t *job_root, const int64_t *job_ep, const double *starts,
                        const double *p, const double *constants, int64_t n_const,
                        const double *folded, int64_t n_folded)
{
    Outcome o;
    double *W = calloc(g->base + (size_t)n_banks * g->M + 1, sizeof *W);
    int64_t *team_stamp = malloc(((size_t)n_teams + 1) * sizeof *team_stamp);
    int64_t *bank_stamp = malloc(((size_t)n_banks + 1) * sizeof *bank_stamp);
    o.returns = malloc(((size_t)n_jobs + 1) * sizeof *o.returns);
    o.counts = malloc(3 * ((size_t)n_jobs + 1) * sizeof *o.counts);
    if (!W || !team_stamp || !bank_stamp || !o.returns || !o.counts) {
        fprintf(stderr, "engine_port: out of memory\n");
        exit(4);
    }
    for (int64_t i = 0; i < n_teams; i++)
        team_stamp[i] = -1;
    for (int64_t i = 0; i < n_banks; i++)
        bank_stamp[i] = -1;
    memcpy(W + g->R, constants, (size_t)n_const * sizeof *W);
    double *obs = W + g->R + n_const;
    memcpy(W + g->base - n_folded, folded, (size_t)n_folded * sizeof *W);
    int64_t stamp = 0;
    for (int64_t j = 0; j < n_jobs; j++) {
        int64_t e = job_ep[j], counts[2] = {0, 0}, t = 0;
        double s[STATE_SIZE], total = 0.0, a_c;
        memcpy(s, starts + e * STATE_SIZE, sizeof s);
        s[PREV_FORCE] = p[FORCE];
        s[STEP] = 0.0;
        obs[0] = clip_obs(s[0] / p[X_THRESHOLD]);
        obs[1] = clip_obs(s[2] / p[THETA_THRESHOLD]);
        for (;;) {
            int a_d = decide(g, job_root[j], W, team_stamp, stamp, bank_stamp, j, counts, &a_c);
            int terminated, truncated;
            stamp++;
            s[STEP] += 1.0;
            terminated = cartpole_step(p, s, a_d);
            truncated = !terminated && s[STEP] >= p[MAX_STEPS];
            total += 1.0;
            t++;
            if (terminated || truncated)
                break;
            obs[0] = clip_obs(s[0] / p[X_THRESHOLD]);
            obs[1] = clip_obs(s[2] / p[THETA_THRESHOLD]);
        }
        o.returns[j] = total;
        o.counts[3 * j] = t;
        o.counts[3 * j + 1] = counts[0];
        o.counts[3 * j + 2] = counts[1];
    }
    free(W);
    free(team_stamp);
    free(bank_stamp);
    return o;
}

int main(int argc, char **argv)
{
    int64_t h[N_HEADER];
    FILE *f;
    Graph g;
    struct timespec t0, t1;
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: %s IN OUT [PASSES]\n", argv[0]);
        return 2;
    }
    long passes = argc == 4 ? strtol(argv[3], NULL, 10) : 2;
    if (passes < 1) {
        fprintf(stderr, "engine_port: PASSES must be at least 1\n");
        return 2;
    }
    f = fopen(argv[1], "rb");
    if (!f || fread(h, sizeof *h, N_HEADER, f) != N_HEADER) {
        fprintf(stderr, "engine_port: cannot read %s\n", argv[1]);
        return 3;
    }
    /* header: n_teams, n_members, n_programs, n_instrs, R, M, base, n_banks, n_jobs, n_pool,
     * noise width, n_constants, n_folded */
    int64_t n_teams = h[0], n_prog = h[2], n_jobs = h[8], width = h[10], n_const = h[11];
    double *limits = read_block(f, 4, sizeof(double));
    if (limits[0] != BIG || limits[1] != DIV_EPS || limits[2] != LOG_BIG || limits[3] != LOG_TINY) {
        fprintf(stderr, "engine_port: the input's protection limits differ from the build's\n");
        return 5;
    }
    g.team_offsets = read_block(f, (size_t)n_teams + 1, sizeof(int64_t));
    g.team_members = read_block(f, (size_t)h[1], sizeof(int64_t));
    g.prog_offsets = read_block(f, (size_t)n_prog + 1, sizeof(int64_t));
    g.instrs = read_block(f, 4 * (size_t)h[3], sizeof(uint32_t));
    g.prog_action = read_block(f, (size_t)n_prog, sizeof(int64_t));
    g.prog_bank = read_block(f, (size_t)n_prog, sizeof(int64_t));
    g.prog_count = read_block(f, (size_t)n_prog, sizeof(int64_t));
    g.R = (size_t)h[4], g.M = (size_t)h[5], g.base = (size_t)h[6];
    int64_t *job_root = read_block(f, (size_t)n_jobs, sizeof(int64_t));
    int64_t *job_ep = read_block(f, (size_t)n_jobs, sizeof(int64_t));
    double *starts = read_block(f, (size_t)h[9] * STATE_SIZE, sizeof(double));
    double *noise = read_block(f, (size_t)h[9] * (size_t)width, sizeof(double));
    double *p = read_block(f, 9, sizeof(double));
    double *constants = read_block(f, (size_t)n_const, sizeof(double));
    double *folded = read_block(f, (size_t)h[12], sizeof(double));
    fclose(f);
    (void)noise; /* CartPole observes both inputs: the noise rows are not read */

    Outcome o = {NULL, NULL};
    for (long pass = 0; pass < passes; pass++) {
        free(o.returns);
        free(o.counts);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
        o = play_all(&g, n_teams, h[7], n_jobs, job_root, job_ep, starts, p, constants, n_const,
                     folded, h[12]);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
    }

    f = fopen(argv[2], "wb");
    if (!f || fwrite(o.returns, sizeof *o.returns, (size_t)n_jobs, f) != (size_t)n_jobs ||
        fwrite(o.counts, sizeof *o.counts, 3 * (size_t)n_jobs, f) != 3 * (size_t)n_jobs ||
        fclose(f)) {
        fprintf(stderr, "engine_port: cannot write %s\n", argv[2]);
        return 3;
    }
    printf("%.9f\n", (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    return 0;
}
