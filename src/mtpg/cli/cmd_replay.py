"""``mtpg replay``: traced test episodes of one task, saved as ``.npz`` and/or a video."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``replay`` command."""
    from mtpg.cli.memory_option import add_memory_option

    p = subparsers.add_parser(
        "replay",
        help="trace a graph's test episodes of one task (npz, GIF or MP4)",
        description="Play test episodes of one task (the episodes mtpg evaluate uses) with "
        "the tracing engine: per step the hidden state, observation, actions, reward, teams "
        "visited, instructions executed, memory reads and writes with the age of each value "
        "read, and every memory register (schema: docs/analysis.md). --video renders the "
        "task beside the graph with the decision path highlighted. A Gymnasium task (gym:ID) "
        "has no hidden state in the trace (the environment keeps it) and its video frames are "
        "the environment's own rgb_array render; one that cannot render is refused.",
    )
    p.add_argument("target", metavar="GRAPH_OR_RUN", help="a graph .json file or a run directory")
    p.add_argument("--task", required=True, help="task name")
    p.add_argument("--episodes", type=int, default=1, help="test episodes (default 1)")
    p.add_argument("--seed", type=int, default=0, help="test seed offset (default 0)")
    p.add_argument("--out", metavar="FILE.npz", help="write the trace to this .npz file")
    p.add_argument(
        "--video",
        metavar="FILE.gif|FILE.mp4",
        help="render the first episode (MP4 needs the video extra)",
    )
    p.add_argument("--max-frames", type=int, help="cut the video after this many frames")
    p.add_argument("--fps", type=int, default=25, help="video frames per second (default 25)")
    add_memory_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    import numpy as np

    from mtpg.analysis.graph.replay import replay_task
    from mtpg.cli.common import resolve_graph, target_task_table, task_list
    from mtpg.cli.main import UsageError
    from mtpg.cli.memory_option import resolve_no_memory
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.taskset.variants import known

    [args.task] = task_list(args.task, "--task")  # a variant checked, spelled canonically
    if not known(args.task):
        raise UsageError(f"unknown task {args.task!r}; choose from {', '.join(TASK_NAMES)}")
    if args.episodes < 1:
        raise UsageError(f"--episodes must be >= 1, got {args.episodes}")
    if args.out and not args.out.endswith(".npz"):
        raise UsageError(f"--out {args.out}: the trace file must end in .npz")
    if args.video and Path(args.video).suffix not in (".gif", ".mp4"):
        raise UsageError(f"--video {args.video}: must end in .gif or .mp4")
    if args.video and Path(args.video).suffix == ".mp4":
        from mtpg.analysis.graph.video import ffmpeg_writer

        ffmpeg_writer(args.fps)  # fail before the replay when ffmpeg is missing
    pop, root, meta, _ = resolve_graph(Path(args.target))
    no_memory, memory_text = resolve_no_memory(args.memory, meta)
    table = target_task_table(Path(args.target), [args.task])
    gym_task = table.spec(args.task) if table.is_gym(table.id_of(args.task)) else None
    if args.video and gym_task is not None:
        from mtpg.analysis.graph.gym_replay import render_refusal

        refusal = render_refusal(gym_task)
        if refusal:  # before the replay: nothing is written
            raise UsageError(refusal)
    if args.video and table.is_user(table.id_of(args.task)):
        raise UsageError(
            f"--video: {args.task} is a compiled task of a user's module, which does not "
            "render; --out FILE.npz writes its trace"
        )
    replay = replay_task(pop, root, args.task, args.episodes, args.seed, no_memory, table=table)
    returns = replay["returns"]
    lengths = np.diff(replay["episode_offsets"])
    print(
        f"{args.target}: root team {root}, {len(replay['team_ids'])} teams; {args.task}, "
        f"{args.episodes} test episode(s) (seed offset {args.seed}); {memory_text}"
    )
    for seed, ret, n in zip(replay["episode_seeds"], returns, lengths, strict=True):
        print(f"  episode seed {int(seed)}: return {ret:.3f} in {int(n)} steps")
    teams = replay.counts("visit")
    print(
        f"mean return {returns.mean():.3f}; teams per step {teams.mean():.2f}; "
        f"instructions per step {replay.counts('instr').mean():.1f}"
    )
    if args.out:
        print(f"wrote {replay.save(args.out)}")
    if args.video:
        from mtpg.analysis.description.layout import layout_graph
        from mtpg.analysis.graph.video import write_video

        images = None
        if gym_task is not None:  # the environment's own frames, the episode played again
            from mtpg.analysis.graph.gym_replay import gym_frames

            images = gym_frames(gym_task, replay, 0, args.max_frames)
        frames = write_video(
            replay,
            layout_graph(pop, root),
            args.video,
            fps=args.fps,
            max_frames=args.max_frames,
            frames=images,
        )
        print(f"wrote {args.video} ({frames} frames)")
    return 0
