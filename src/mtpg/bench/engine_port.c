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
 * Usage: engine_port IN OUT [PASSES [LANES]]. LANES > 0 plays up to LANES consecutive jobs of
 * one root in lockstep (play_all_lanes, the yardstick of the lane engine); 0, the default,
 * one job at a time (play_all, the yardstick of the scalar kernel). IN holds the compiled graph and the episodes (layout
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

/* Protected power (Table 2): |a|^b, 0 for a = 0, BIG past overflow, 0 past underflow. */
static inline double op_pow(double a, double b)
{
    double x = fabs(a), e;
    if (x == 0.0)
        return 0.0;
    e = b * log(x);
    if (e > LOG_BIG)
        return BIG;
    if (e < LOG_TINY)
        return 0.0;
    return pow(x, b);
}

/* The protected operations of Table 2 and the engine's copy (mtpg.engine.ops.apply_op). */
static double apply_op(uint32_t op, double d, double a, double b)
{
    double v;
    switch (op) {
    case 0: v = a + b; break;
    case 1: v = a - b; break;
    case 2: v = a * b; break;
    case 3: v = fabs(b) < DIV_EPS ? a : a / b; break;
    case 4: v = op_pow(a, b); break;
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

/* One operation over a lane group: D[l] = clamp(EXPR) for each lane l of grp, where a, b, d
 * are the lane's operands (value v of lane l lives at W[v * L + l]). */
#define OVER_GROUP(EXPR)                                                                     \
    for (int64_t k = 0; k < ng; k++) {                                                       \
        size_t l = (size_t)grp[k];                                                           \
        double a = A[l], b = B[l], d = D[l];                                                 \
        (void)a, (void)d;                                                                    \
        D[l] = clamp(EXPR);                                                                  \
    }                                                                                        \
    break

/* Lane mode (mtpg.engine.lanes' design, the C yardstick of `--lanes N`): up to L
 * consecutive jobs of one root are played in lockstep. Each decision step, the live lanes
 * at the same team form a group and every program of the team runs once over the group,
 * one loop over the group's lanes per instruction, on a lane-contiguous workspace (value
 * v of lane l at W[v * L + l]; the constants stored per lane, so one index rule serves
 * every operand). Bids, the visited-team rule, lazy bank zeroing and the counts are per
 * lane, as in the scalar mode, so every job's outcome is the same. */
static Outcome play_all_lanes(const Graph *g, int64_t n_teams, int64_t n_banks, int64_t n_jobs,
                              const int64_t *job_root, const int64_t *job_ep,
                              const double *starts, const double *p, const double *constants,
                              int64_t n_const, const double *folded, int64_t n_folded, int64_t L)
{
    Outcome o;
    size_t Lz = (size_t)L, n_values = g->base + (size_t)n_banks * g->M;
    double *W = calloc(n_values * Lz + 1, sizeof *W);
    int64_t *visited = malloc(((size_t)n_teams * Lz + 1) * sizeof *visited);
    int64_t *bank_job = malloc(((size_t)n_banks * Lz + 1) * sizeof *bank_job);
    int64_t *lane = malloc(10 * Lz * sizeof *lane); /* the per-lane integer arrays below */
    double *lane_f = malloc((4 + STATE_SIZE) * Lz * sizeof *lane_f);
    o.returns = malloc(((size_t)n_jobs + 1) * sizeof *o.returns);
    o.counts = malloc(3 * ((size_t)n_jobs + 1) * sizeof *o.counts);
    if (!W || !visited || !bank_job || !lane || !lane_f || !o.returns || !o.counts) {
        fprintf(stderr, "engine_port: out of memory\n");
        exit(4);
    }
    int64_t *job = lane, *steps = lane + Lz, *n_team = lane + 2 * Lz, *n_ins = lane + 3 * Lz,
            *live = lane + 4 * Lz, *at = lane + 5 * Lz, *pend = lane + 6 * Lz,
            *grp = lane + 7 * Lz, *best_p = lane + 8 * Lz, *a_d = lane + 9 * Lz;
    double *total = lane_f, *best = lane_f + Lz, *a_c = lane_f + 2 * Lz,
           *S = lane_f + 4 * Lz; /* lane l's state at S + l * STATE_SIZE */
    for (size_t i = 0; i < (size_t)n_teams * Lz; i++)
        visited[i] = -1;
    for (size_t i = 0; i < (size_t)n_banks * Lz; i++)
        bank_job[i] = -1;
    for (size_t l = 0; l < Lz; l++) {
        for (int64_t c = 0; c < n_const; c++)
            W[(g->R + (size_t)c) * Lz + l] = constants[c];
        for (int64_t c = 0; c < n_folded; c++)
            W[(g->base - (size_t)n_folded + (size_t)c) * Lz + l] = folded[c];
    }
    double *obs0 = W + (g->R + (size_t)n_const) * Lz, *obs1 = obs0 + Lz;
    int64_t stamp = 0;
    for (int64_t j0 = 0; j0 < n_jobs;) {
        int64_t nl = 1, root = job_root[j0], n_live;
        while (nl < L && j0 + nl < n_jobs && job_root[j0 + nl] == root)
            nl++;
        for (int64_t l = 0; l < nl; l++) {
            double *s = S + l * STATE_SIZE;
            job[l] = j0 + l;
            memcpy(s, starts + job_ep[j0 + l] * STATE_SIZE, STATE_SIZE * sizeof *s);
            s[PREV_FORCE] = p[FORCE];
            s[STEP] = 0.0;
            obs0[l] = clip_obs(s[0] / p[X_THRESHOLD]);
            obs1[l] = clip_obs(s[2] / p[THETA_THRESHOLD]);
            steps[l] = n_team[l] = n_ins[l] = 0;
            total[l] = 0.0;
            live[l] = l;
        }
        n_live = nl;
        while (n_live > 0) {
            int64_t n_pend = n_live;
            stamp++;
            for (int64_t k = 0; k < n_live; k++) {
                pend[k] = live[k];
                at[live[k]] = root;
            }
            while (n_pend > 0) { /* one group: the pending lanes at the first one's team */
                int64_t team = at[pend[0]], ng = 0, keep = 0;
                for (int64_t k = 0; k < n_pend; k++) {
                    if (at[pend[k]] == team)
                        grp[ng++] = pend[k];
                    else
                        pend[keep++] = pend[k];
                }
                n_pend = keep;
                for (int64_t k = 0; k < ng; k++) {
                    visited[team * L + grp[k]] = stamp;
                    n_team[grp[k]]++;
                    best_p[grp[k]] = -1;
                }
                for (int64_t m = g->team_offsets[team]; m < g->team_offsets[team + 1]; m++) {
                    int64_t pr = g->team_members[m], bank = g->prog_bank[pr], act;
                    size_t bank_v = g->base + (size_t)bank * g->M;
                    for (int64_t k = 0; k < ng; k++) {
                        size_t l = (size_t)grp[k];
                        if (bank_job[(size_t)bank * Lz + l] != job[l]) {
                            for (size_t i = 0; i < g->M; i++)
                                W[(bank_v + i) * Lz + l] = 0.0;
                            bank_job[(size_t)bank * Lz + l] = job[l];
                        }
                        for (size_t i = 0; i < g->R; i++)
                            W[i * Lz + l] = 0.0;
                    }
                    for (int64_t i = g->prog_offsets[pr]; i < g->prog_offsets[pr + 1]; i++) {
                        const uint32_t *in = g->instrs + 4 * i;
                        double *D = W + (size_t)in[1] * Lz;
                        const double *A = W + (size_t)in[2] * Lz, *B = W + (size_t)in[3] * Lz;
                        switch (in[0]) {
                        case 0: OVER_GROUP(a + b);
                        case 1: OVER_GROUP(a - b);
                        case 2: OVER_GROUP(a * b);
                        case 3: OVER_GROUP(fabs(b) < DIV_EPS ? a : a / b);
                        case 4: OVER_GROUP(op_pow(a, b));
                        case 5: OVER_GROUP(cos(b));
                        case 6: OVER_GROUP(b == 0.0 ? 0.0 : log(fabs(b)));
                        case 7: OVER_GROUP(b > LOG_BIG ? BIG : exp(b));
                        case 8: OVER_GROUP(sqrt(fabs(b)));
                        case 9: OVER_GROUP(sin(b));
                        case 10: OVER_GROUP(tanh(b));
                        case 11: OVER_GROUP(b * b);
                        case 12: OVER_GROUP(fabs(b));
                        case 13: OVER_GROUP(b * b * b);
                        case 14: OVER_GROUP(a < b ? -d : d);
                        case 15: OVER_GROUP(a > b ? -d : d);
                        default: /* OP_COPY of a folded constant: within [-BIG, BIG] already */
                            for (int64_t k = 0; k < ng; k++)
                                D[grp[k]] = B[grp[k]];
                        }
                    }
                    act = g->prog_action[pr];
                    for (int64_t k = 0; k < ng; k++) {
                        int64_t l = grp[k];
                        n_ins[l] += g->prog_count[pr];
                        if ((act < 0 || visited[act * L + l] != stamp) &&
                            (best_p[l] < 0 || W[l] > best[l])) {
                            best[l] = W[l];
                            best_p[l] = pr;
                        }
                    }
                }
                for (int64_t k = 0; k < ng; k++) {
                    int64_t l = grp[k], act = g->prog_action[best_p[l]];
                    if (act < 0) {
                        size_t v = g->base + (size_t)g->prog_bank[best_p[l]] * g->M;
                        a_c[l] = W[v * Lz + (size_t)l];
                        a_d[l] = -1 - act;
                    } else {
                        at[l] = act;
                        pend[n_pend++] = l;
                    }
                }
            }
            int64_t keep = 0;
            for (int64_t k = 0; k < n_live; k++) { /* every live lane steps */
                int64_t l = live[k];
                double *s = S + l * STATE_SIZE;
                int terminated, truncated;
                (void)a_c[l]; /* CartPole reads the discrete action */
                s[STEP] += 1.0;
                terminated = cartpole_step(p, s, (int)a_d[l]);
                truncated = !terminated && s[STEP] >= p[MAX_STEPS];
                total[l] += 1.0;
                steps[l]++;
                if (terminated || truncated) {
                    o.returns[job[l]] = total[l];
                    o.counts[3 * job[l]] = steps[l];
                    o.counts[3 * job[l] + 1] = n_team[l];
                    o.counts[3 * job[l] + 2] = n_ins[l];
                } else {
                    obs0[l] = clip_obs(s[0] / p[X_THRESHOLD]);
                    obs1[l] = clip_obs(s[2] / p[THETA_THRESHOLD]);
                    live[keep++] = l;
                }
            }
            n_live = keep;
        }
        j0 += nl;
    }
    free(W);
    free(visited);
    free(bank_job);
    free(lane);
    free(lane_f);
    return o;
}

int main(int argc, char **argv)
{
    int64_t h[N_HEADER];
    FILE *f;
    Graph g;
    struct timespec t0, t1;
    if (argc < 3 || argc > 5) {
        fprintf(stderr, "usage: %s IN OUT [PASSES [LANES]]\n", argv[0]);
        return 2;
    }
    long passes = argc >= 4 ? strtol(argv[3], NULL, 10) : 2;
    long lanes = argc == 5 ? strtol(argv[4], NULL, 10) : 0;
    if (lanes < 0) {
        fprintf(stderr, "engine_port: LANES must be at least 0\n");
        return 2;
    }
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
        if (lanes > 0)
            o = play_all_lanes(&g, n_teams, h[7], n_jobs, job_root, job_ep, starts, p, constants,
                               n_const, folded, h[12], lanes);
        else
            o = play_all(&g, n_teams, h[7], n_jobs, job_root, job_ep, starts, p, constants,
                         n_const, folded, h[12]);
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
