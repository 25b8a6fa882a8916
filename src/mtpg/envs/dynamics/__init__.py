"""Task dynamics: the compiled kernels of each task and the one dispatch on the task id.

- one module per task family (:mod:`~mtpg.envs.dynamics.cartpole`, ``acrobot``,
  ``cartcentering``, ``mountaincar``, ``pendulum``): its start sampler, ``step`` and
  ``observe``, reading a parameter row whose columns are the spec's ``param_names``;
- :mod:`~mtpg.envs.dynamics.dispatch`: ``env_reset``, ``env_observe``, ``env_step``, the
  calls every engine kernel makes, branching on a row's task kind;
- :mod:`~mtpg.envs.dynamics.rollout`: compiled episode runners for measurements;
- :mod:`~mtpg.envs.dynamics.numeric`: small helpers shared by the task kernels.

This layer imports only :mod:`mtpg.envs.specs`.
"""
