"""Choosing the evaluation backend from the configuration."""

import sys

import pytest

from mtpg.config import ConfigError, build_config
from mtpg.engine.evaluator import LocalEvaluator
from mtpg.evolve.backend import make_evaluator


def config(*overrides):
    return build_config("demo", overrides=list(overrides))


def test_local_is_the_default_and_uses_the_workers_threads():
    ev = make_evaluator(config("workers=3"))
    assert isinstance(ev, LocalEvaluator) and ev.threads == 3
    ev.check()  # never lost


def test_dask_backend_needs_an_address_or_workers_not_both():
    with pytest.raises(ConfigError, match="address"):
        make_evaluator(config("backend=dask"))
    with pytest.raises(ConfigError, match="address"):
        make_evaluator(config("backend=dask", "dask_workers=2", 'address="tcp://127.0.0.1:1"'))
    with pytest.raises(ConfigError, match="backend"):
        config("backend=ray")
    with pytest.raises(ConfigError, match="dask_workers"):
        config("dask_workers=-1")


def test_dask_backend_without_its_packages_is_one_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails as if absent
    with pytest.raises(ConfigError, match=r"pip install 'mtpg\[dask\]'") as info:
        make_evaluator(config("backend=dask", "dask_workers=2"))
    assert "\n" not in str(info.value)


def test_train_options_become_settings():
    from mtpg.cli.common import overrides
    from mtpg.cli.main import build_parser

    args = build_parser().parse_args(
        ["train", "--backend", "dask", "--address", "tcp://10.0.0.1:8786", "--dask-workers", "0"]
    )
    cfg = build_config("demo", overrides=overrides(args))
    assert (cfg.backend, cfg.address, cfg.dask_workers) == ("dask", "tcp://10.0.0.1:8786", 0)
