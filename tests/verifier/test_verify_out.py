"""What verify writes stays inside --out: a witness folder planted as a link (or a file) is refused before any
work, and a link planted while it runs is never followed (issue 29); --workers is bounded."""

from __future__ import annotations

import pytest

from cellstress.cli import main
from cellstress.core.cpus import max_workers

ARGS = ["verify", "s1-scanner-width", "--phases", "cell", "--horizon", "4", "--workers", "1"]


@pytest.mark.parametrize("planted", ["link", "file"])
def test_a_planted_witness_folder_is_refused(tmp_path, capsys, planted):
    out, victim = tmp_path / "out", tmp_path / "victim"
    out.mkdir()
    victim.mkdir()
    if planted == "link":
        (out / "witness-01").symlink_to(victim)
    else:
        (out / "witness-01").write_text("mine\n")
    code = main([*ARGS, "--out", str(out)])
    err = capsys.readouterr().err
    kind = "a symbolic link" if planted == "link" else "not a folder"
    assert code == 2 and err.count("\n") == 1 and err.startswith(f"error: {out / 'witness-01'}: is {kind}"), err
    assert list(victim.iterdir()) == []
    assert sorted(p.name for p in out.iterdir()) == ["witness-01"]  # nothing decided, nothing written


def test_a_link_planted_during_the_run_is_not_followed(tmp_path, monkeypatch):
    """The check before the run cannot see a link planted later: the witness writer itself opens each folder
    without following links."""
    from cellstress.core.io import OutputPathError
    from cellstress.verifier import run

    out, victim = tmp_path / "out", tmp_path / "victim"
    out.mkdir()
    victim.mkdir()
    real = run.assemble

    def plant_then_assemble(*args, **kwargs):
        (out / "witness-01").symlink_to(victim)
        return real(*args, **kwargs)

    monkeypatch.setattr(run, "assemble", plant_then_assemble)
    from cellstress.sim.simulator import Simulator

    with pytest.raises(OutputPathError, match="witness-01: is a symbolic link"):
        run.verify_cell(Simulator("s1-scanner-width"), horizon=4, phases="cell", out=out)
    assert list(victim.iterdir()) == []


def test_the_witnesses_are_written_when_nothing_is_planted(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*ARGS, "--out", str(out)]) == 1
    assert (out / "witness-01" / "result.json").is_file() and not (out / "witness-01").is_symlink()


@pytest.mark.parametrize("workers", [0, -1, 10**6])
def test_workers_are_bounded(tmp_path, capsys, workers):
    """--workers 1000000 started 42 processes on 2 cores (issue 29): above 4 per usable core is refused."""
    code = main([*ARGS[:-2], "--workers", str(workers), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and f"--workers must be a whole number in 1..{max_workers()}" in err
    assert not (tmp_path / "out").exists()
