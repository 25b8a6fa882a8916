"""A run's set of tasks: variants, the task table, reference scores, episodes and seeds.

- :mod:`~mtpg.envs.taskset.variants`: ``Base[key=value]`` names parsed into specs and rows;
- :mod:`~mtpg.envs.taskset.task_table`: the :class:`TaskTable` value a run is given;
- :mod:`~mtpg.envs.taskset.reference_scores`: the reference scores and normalisation;
- :mod:`~mtpg.envs.taskset.episodes`: start states and noise drawn from episode seeds;
- :mod:`~mtpg.envs.taskset.episode_seeds`: which seeds train, test (held out), validate
  and measure random play.

This layer builds on :mod:`mtpg.envs.specs` and :mod:`mtpg.envs.dynamics`.
"""
