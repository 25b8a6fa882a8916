"""Replay videos: the task rendered beside the team graph, the decision path highlighted.

One frame per decision: the task as it was when the decision was made (the state before
the step) and the path of teams visited (green; the team that chose the action has a
thick outline). GIF files need only matplotlib and Pillow; MP4 files need an ffmpeg
program, which the ``video`` extra installs (``pip install -e ".[video]"`` in the checkout).
"""

from __future__ import annotations

import os
from pathlib import Path

from mtpg.analysis.description.layout import GraphDrawing, GraphLayout
from mtpg.analysis.graph.replay import Replay
from mtpg.analysis.palette import task_colour
from mtpg.analysis.plotting import pyplot
from mtpg.envs.gym_api.render import make_renderer
from mtpg.envs.taskset.variants import task_spec

#: File endings of the formats written.
VIDEO_SUFFIXES = (".gif", ".mp4")


def ffmpeg_writer(fps: int):
    """The FFMpegWriter of matplotlib, using the ffmpeg of the ``video`` extra (or on PATH).

    Raises:
        ValueError: When no ffmpeg program is available (one line telling what to install).
    """
    import matplotlib
    from matplotlib.animation import FFMpegWriter

    try:
        import imageio_ffmpeg

        matplotlib.rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        pass
    if not FFMpegWriter.isAvailable():
        raise ValueError(
            'MP4 needs ffmpeg: install the extra with pip install -e ".[video]" in the '
            "mtpg checkout (or write a .gif instead)"
        )
    return FFMpegWriter(fps=fps)


def write_video(
    replay: Replay,
    layout: GraphLayout,
    path: str | Path,
    episode: int = 0,
    fps: int = 25,
    max_frames: int | None = None,
    dpi: int = 72,
    frames: list | None = None,
) -> int:
    """Writes one episode of a replay as a GIF or MP4 video.

    Args:
        replay: The replay.
        layout: Layout of the replayed graph.
        path: Output file ending in ``.gif`` or ``.mp4``.
        episode: Which episode of the replay.
        fps: Frames per second.
        max_frames: Stop after this many frames (None: the whole episode).
        dpi: Resolution of the frames.
        frames: The task's images, one per step of the episode from its first (a
            Gymnasium task's own, :func:`~mtpg.analysis.graph.gym_replay.gym_frames`);
            None: drawn from the replay's hidden states by mtpg's renderer.

    Returns:
        The number of frames written (the episode length, unless ``max_frames`` cuts it).
    """
    from matplotlib.animation import PillowWriter

    path = Path(path)
    if path.suffix not in VIDEO_SUFFIXES:
        raise ValueError(f"{path}: a video must end in .gif or .mp4")
    writer = PillowWriter(fps=fps) if path.suffix == ".gif" else ffmpeg_writer(fps)
    plt = pyplot()
    sl = replay.episode_slice(episode)
    steps = range(sl.start, sl.stop if max_frames is None else min(sl.stop, sl.start + max_frames))
    # frames are drawn off-screen: no display is needed (and SDL stays quiet without one)
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    renderer = None if frames is not None else make_renderer(task_spec(replay.task))
    task = replay.task
    fig, (ax_task, ax_graph) = plt.subplots(
        1, 2, figsize=(9, 4), gridspec_kw={"width_ratios": [1.3, 1]}
    )
    drawing = GraphDrawing(ax_graph, layout, font_size=8)
    ax_graph.set_title("team graph (green: decision path)", fontsize=9)
    image = None
    visits = replay.per_step("visit", "visit_team")
    ret = 0.0
    count = 0
    try:
        with writer.saving(fig, str(path), dpi):
            for i in steps:
                if renderer is None:
                    frame = frames[i - sl.start]
                else:
                    prev = replay["a_c"][i - 1] if i > sl.start else 0.0
                    frame = renderer.frame(replay["hidden_state"][i], float(prev))
                if image is None:
                    image = ax_task.imshow(frame)
                    ax_task.set_xticks([])
                    ax_task.set_yticks([])
                else:
                    image.set_data(frame)
                path_teams = [int(t) for t in visits[i]]
                drawing.highlight(path_teams)
                ret += float(replay["reward"][i])
                ax_task.set_title(
                    f"{task}  step {i - sl.start}  a_d={int(replay['a_d'][i])} "
                    f"a_c={replay['a_c'][i]:+.2f}  return {ret:.1f}",
                    fontsize=9,
                    color=task_colour(task),
                )
                fig.suptitle("path: " + " > ".join(map(str, path_teams)), fontsize=9, x=0.7, y=0.08)
                writer.grab_frame()
                count += 1
    finally:
        if renderer is not None:
            renderer.close()
        plt.close(fig)
    return count
