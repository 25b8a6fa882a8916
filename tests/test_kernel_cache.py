"""The kernel cache guard: Numba's cache goes when any source of the package changes."""

from __future__ import annotations

from pathlib import Path

from mtpg._kernel_cache import cached_kernels, fingerprint, refresh


def _package(tmp_path: Path) -> tuple[Path, Path]:
    root = tmp_path / "pkg"
    (root / "sub" / "__pycache__").mkdir(parents=True)
    (root / "a.py").write_text("x = 1\n")
    (root / "sub" / "b.py").write_text("y = 2\n")
    return root, root / "__pycache__" / "stamp"


def _compile(root: Path) -> None:
    for name in ("b.f-1.py311.nbi", "b.f-1.py311.1.nbc", "b.cpython-311.pyc"):
        (root / "sub" / "__pycache__" / name).write_text("cached")


def test_an_edit_in_another_module_clears_every_cached_kernel(tmp_path: Path) -> None:
    root, stamp = _package(tmp_path)
    _compile(root)
    assert refresh(root, stamp)  # first sight: no stamp, so the cache cannot be trusted
    assert cached_kernels(root) == []
    _compile(root)
    assert not refresh(root, stamp) and len(cached_kernels(root)) == 2  # sources unchanged
    (root / "a.py").write_text("x = 3\n")  # an edit in a module that defines no kernel here
    assert refresh(root, stamp) and cached_kernels(root) == []
    assert (root / "sub" / "__pycache__" / "b.cpython-311.pyc").exists()  # Python's own stays


def test_the_fingerprint_covers_paths_and_bytes(tmp_path: Path) -> None:
    root, _ = _package(tmp_path)
    before = fingerprint(root)
    (root / "sub" / "b.py").rename(root / "sub" / "c.py")
    assert fingerprint(root) != before


def test_the_installed_package_is_stamped_with_its_sources() -> None:
    import mtpg._kernel_cache as guard

    refresh()  # as the command line and the suite's start do
    assert guard._STAMP.read_text() == fingerprint()


def test_the_command_line_refreshes_before_its_command_runs(monkeypatch, capsys) -> None:
    import mtpg._kernel_cache as guard
    from mtpg.cli.main import main

    def refresh() -> bool:
        raise RuntimeError("refreshed")

    monkeypatch.setattr(guard, "refresh", refresh)
    assert main([]) == 2  # no command (the help): nothing to refresh for
    assert "refreshed" not in capsys.readouterr().err
    assert main(["show", "no-such-graph.json"]) == 1  # the refresh came before the command
    assert "internal error: RuntimeError: refreshed" in capsys.readouterr().err
