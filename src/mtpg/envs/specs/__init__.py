"""What a task is, as data: the bottom layer of :mod:`mtpg.envs`, no Numba.

- :mod:`~mtpg.envs.specs.task_spec`: the :class:`TaskSpec` record and its reference scores;
- :mod:`~mtpg.envs.specs.registry`: the registered tasks, one spec each, in task-id order;
- :mod:`~mtpg.envs.specs.contract`: the task ids and the state slots the kernels share;
- :mod:`~mtpg.envs.specs.param_table`: the registered tasks' parameters as NumPy arrays.

Gymnasium registration reads only this layer, so ``import mtpg`` stays light.
"""
