"""The Gymnasium face of the tasks: environments, their registration and frames.

- :mod:`~mtpg.envs.gym_api.env`: :class:`MtpgEnv`, one class for every task and variant;
- :mod:`~mtpg.envs.gym_api.multitask`: ``mtpg/MultiTask-v0``, the tasks as one environment;
- :mod:`~mtpg.envs.gym_api.registration`: the ``mtpg/<Task>-v0`` ids (Gymnasium only);
- :mod:`~mtpg.envs.gym_api.render`: frames of the tasks.

The top layer: it plays the kernels of :mod:`mtpg.envs.dynamics` on the episodes of
:mod:`mtpg.envs.taskset`.
"""
