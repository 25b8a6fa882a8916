"""The task registry: one :class:`~mtpg.envs.specs.task_spec.TaskSpec` per task, in task-id order.

Every per-task table of the package is derived from :data:`TASKS`: the parameter table
and action facts (:mod:`mtpg.envs.specs.param_table`), the task names and ids
(:mod:`mtpg.envs.specs.contract`), the start samplers (:mod:`mtpg.envs.taskset.episodes`),
the reference scores (:mod:`mtpg.envs.taskset.reference_scores`), the renderers, the
Gymnasium ids, the analyses' velocity slots and colours and the progress lines' short
names. The id of a task is its index here; the compiled dispatch
(:func:`mtpg.envs.dynamics.dispatch.task_step`) branches on these ids, and
``tests/envs/test_dispatch.py`` plays every registered task through every kernel.

This module imports nothing heavy (no NumPy, no Numba), so Gymnasium registration stays
light. Reference ``random`` / ``random_std`` figures: measured with
``mtpg.envs.taskset.reference_scores.measure_random(task)`` (10,000 episodes), numpy 2.4, numba
0.68; re-measured by ``tests/envs/test_reference.py`` (slow).
"""

from __future__ import annotations

import math

from mtpg.envs.specs.task_spec import NONE, Reference, TaskSpec

_PI = math.pi

CARTPOLE = TaskSpec(
    name="CartPole",
    short="CP",
    kernel_module="mtpg.envs.dynamics.cartpole",
    step="step",
    observe="observe",
    sample_start="sample_start",
    params=(
        200.0,  # time limit (as CartPole-v0)
        10.0,  # force magnitude [N]
        0.02,  # tau [s]
        9.8,  # gravity
        1.0,  # cart mass [kg]
        0.1,  # pole mass [kg]
        0.5,  # half the pole length [m]
        2.4,  # |x| failure threshold [m]
        12 * 2 * math.pi / 360,  # |theta| failure threshold [rad]
    ),
    param_names=(
        "max_steps",
        "force",
        "tau",
        "gravity",
        "masscart",
        "masspole",
        "length",
        "x_threshold",
        "theta_threshold",
    ),
    state_names=("x", "x_dot", "theta", "theta_dot"),
    # x and theta: their failure thresholds; the velocities: ranges a balancing episode
    # stays well within (Gymnasium leaves them unbounded).
    state_low=(-2.4, -3.0, -12 * 2 * math.pi / 360, -3.5),
    state_high=(2.4, 3.0, 12 * 2 * math.pi / 360, 3.5),
    angle_slots=(),
    observed_slots=(0, 2),
    observed="x/2.4, theta/0.2094",
    action="discrete",
    action_text="a_d: +10N/prev/-10N",
    # best = solved = 195, Gym/Gymnasium CartPole-v0 reward_threshold.
    reference=Reference(18.9678, 10.431719089392697, 195.0, 195.0, "CartPole-v0 reward_threshold"),
    velocity_slot=3,  # the pole's angular velocity: the one its control depends on most
    colour="#1f77b4",
    render="CartPoleEnv",
)

ACROBOT = TaskSpec(
    name="Acrobot",
    short="AB",
    kernel_module="mtpg.envs.dynamics.acrobot",
    step="step",
    observe="observe",
    sample_start="sample_start",
    params=(
        500.0,  # time limit (Acrobot-v1)
        1.0,  # torque bound [N m] (Gymnasium's discrete torques are -1, 0, +1)
        0.2,  # dt [s], one RK4 step
        1.0,  # length of link 1 [m]
        1.0,  # mass of link 1 [kg]
        1.0,  # mass of link 2 [kg]
        0.5,  # centre of mass of link 1 [m]
        0.5,  # centre of mass of link 2 [m]
        1.0,  # moment of inertia of both links
        9.8,  # gravity
        4 * math.pi,  # |dtheta1| bound
        9 * math.pi,  # |dtheta2| bound
    ),
    param_names=(
        "max_steps",
        "max_torque",
        "dt",
        "link_length_1",
        "link_mass_1",
        "link_mass_2",
        "link_com_pos_1",
        "link_com_pos_2",
        "link_moi",
        "gravity",
        "max_vel_1",
        "max_vel_2",
    ),
    state_names=("theta1", "theta2", "dtheta1", "dtheta2"),
    state_low=(-_PI, -_PI, -4 * _PI, -9 * _PI),
    state_high=(_PI, _PI, 4 * _PI, 9 * _PI),
    angle_slots=(0, 1),
    observed_slots=(0, 1),
    observed="theta1/pi, theta2/pi",
    action="continuous",
    action_text="a_c: torque in [-1,1]",
    # best = solved = -100, Gym/Gymnasium Acrobot-v1 reward_threshold (the paper's D4PG
    # figure could not be traced for Gym's Acrobot; spec/environments.md).
    reference=Reference(-500.0, 0.0, -100.0, -100.0, "Acrobot-v1 reward_threshold"),
    velocity_slot=2,  # the first joint's (the paper's choice)
    colour="#ff7f0e",
    render="AcrobotEnv",
)

CARTCENTERING = TaskSpec(
    name="CartCentering",
    short="CC",
    kernel_module="mtpg.envs.dynamics.cartcentering",
    step="step",
    observe="observe",
    sample_start="sample_start",
    params=(
        500.0,  # time limit (10 s)
        1.0,  # force magnitude [N]
        0.02,  # tau [s]
        2.0,  # cart mass [kg]
        6.0,  # |v| bound [m/s]
        1.5,  # |x| bound: the episode ends beyond it [m]
        0.01,  # capture box half-width, for both x and v
        0.75,  # start x, v ~ U[-0.75, 0.75]
        0.1,  # weight of the elapsed-time term of the terminal penalty
    ),
    param_names=(
        "max_steps",
        "force",
        "tau",
        "mass",
        "max_speed",
        "x_bound",
        "capture",
        "start_range",
        "time_cost",
    ),
    state_names=("x", "v"),
    state_low=(-1.5, -6.0),
    state_high=(1.5, 6.0),
    angle_slots=(),
    observed_slots=(0,),
    observed="x/1.5, noise",
    action="discrete",
    action_text="a_d: +1N/prev/-1N",
    # best = mean score of Koza's time-optimal law under this implementation on the test
    # episodes (seeds 1_000_000..1_000_099), measure_time_optimal_cartcentering(); all 100
    # captured, mean 126.73 steps. No registered threshold.
    reference=Reference(
        -0.9873404751314238,
        0.2377274856515104,
        -0.028608253024208153,
        NONE,
        "time-optimal law, measured on the test seeds",
    ),
    velocity_slot=1,
    colour="#2ca02c",
    render="",
)

PENDULUM = TaskSpec(
    name="Pendulum",
    short="PD",
    kernel_module="mtpg.envs.dynamics.pendulum",
    step="step",
    observe="observe",
    sample_start="sample_start",
    params=(
        200.0,  # time limit
        2.0,  # torque bound
        0.05,  # dt [s]
        10.0,  # gravity
        1.0,  # mass [kg]
        1.0,  # length [m]
        8.0,  # |theta_dot| bound
    ),
    param_names=("max_steps", "max_torque", "dt", "gravity", "mass", "length", "max_speed"),
    state_names=("theta", "theta_dot"),
    state_low=(-_PI, -8.0),
    state_high=(_PI, 8.0),
    angle_slots=(0,),
    observed_slots=(0,),
    observed="wrap(theta)/pi, noise",
    action="continuous",
    action_text="a_c: torque in [-2,2]",
    # best = -123.11 +- 6.86, D4PG (msinto93), the top Pendulum-v0 entry of the OpenAI Gym
    # wiki leaderboard, 100 test episodes. No registered threshold.
    reference=Reference(
        -1234.575608635256, 289.45830639340454, -123.11, NONE, "Gym leaderboard, D4PG"
    ),
    velocity_slot=1,
    colour="#d62728",
    render="PendulumEnv",
)

_MC_PARAMS = (
    "max_steps", "force", "gravity", "min_position", "max_position", "max_speed",
    "goal_position", "goal_velocity", "goal_reward", "action_cost", "power",
)  # fmt: skip

_MC_STATE = dict(
    state_names=("position", "velocity"),
    state_low=(-1.2, -0.07),
    state_high=(0.6, 0.07),
    angle_slots=(),
    observed_slots=(0,),
    observed="2(x+1.2)/1.8-1, noise",
    velocity_slot=1,
)

MOUNTAINCAR = TaskSpec(
    name="MountainCar",
    short="MC",
    kernel_module="mtpg.envs.dynamics.mountaincar",
    step="step_discrete",
    observe="observe",
    sample_start="sample_start",
    params=(
        200.0,  # time limit
        0.001,  # force of a push
        0.0025,  # gravity
        -1.2,  # minimum position
        0.6,  # maximum position
        0.07,  # |velocity| bound
        0.5,  # goal position
        0.0,  # goal velocity
        0.0,  # goal reward (unused)
        0.0,  # action cost (unused)
        0.0,  # engine power (unused)
    ),
    param_names=_MC_PARAMS,
    action="discrete",
    action_text="a_d: +1/0/-1 push",
    # best = solved = -110, Gym/Gymnasium MountainCar-v0 reward_threshold.
    reference=Reference(-200.0, 0.0, -110.0, -110.0, "MountainCar-v0 reward_threshold"),
    colour="#9467bd",
    render="MountainCarEnv",
    **_MC_STATE,
)

MOUNTAINCARCONTINUOUS = TaskSpec(
    name="MountainCarContinuous",
    short="MCC",
    kernel_module="mtpg.envs.dynamics.mountaincar",
    step="step_continuous",
    observe="observe",
    sample_start="sample_start",
    params=(
        999.0,  # time limit
        1.0,  # force bound; the force is scaled by the power below
        0.0025,  # gravity
        -1.2,  # minimum position
        0.6,  # maximum position
        0.07,  # |velocity| bound
        0.45,  # goal position
        0.0,  # goal velocity
        100.0,  # reward on reaching the goal
        0.1,  # cost per squared (clipped) force
        0.0015,  # engine power: the velocity change is force * power
    ),
    param_names=_MC_PARAMS,
    action="continuous",
    action_text="a_c: force in [-1,1]",
    # best = solved = 90, Gym/Gymnasium MountainCarContinuous-v0 reward_threshold.
    reference=Reference(
        -33.10653758859584, 4.803512011466331, 90.0, 90.0, "MountainCarContinuous-v0 threshold"
    ),
    colour="#8c564b",
    render="Continuous_MountainCarEnv",
    **_MC_STATE,
)

#: Every task, in id order: the id of a task is its index here.
TASKS: tuple[TaskSpec, ...] = (
    CARTPOLE,
    ACROBOT,
    CARTCENTERING,
    PENDULUM,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
)

#: Task names in id order.
TASK_NAMES: tuple[str, ...] = tuple(t.name for t in TASKS)

#: The paper's six tasks (Table 1): the default task set of a run, whatever else is
#: registered, so that registering a task changes no existing configuration.
PAPER_TASKS: tuple[str, ...] = tuple(
    t.name for t in (CARTPOLE, ACROBOT, CARTCENTERING, PENDULUM, MOUNTAINCAR, MOUNTAINCARCONTINUOUS)
)

if len(set(TASK_NAMES)) != len(TASKS) or len({t.short for t in TASKS}) != len(TASKS):
    raise ValueError("task names and short names must be unique")


def task_id(name: str) -> int:
    """The id of a task name.

    Raises:
        ValueError: Naming the known tasks, for an unknown name.
    """
    if name not in TASK_NAMES:
        raise ValueError(f"unknown task {name!r}; choose from {', '.join(TASK_NAMES)}")
    return TASK_NAMES.index(name)


def spec(task: int | str) -> TaskSpec:
    """The spec of a task id or name."""
    return TASKS[task_id(task) if isinstance(task, str) else int(task)]
