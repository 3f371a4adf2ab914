"""The same small campaign gives the same runs.jsonl lines on 1 worker, 2 worker processes and Ray."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

from cellstress.campaign import Backend, resolve, run_campaign
from cellstress.campaign.store import RUNS
from cellstress.campaign.worker import execute
from cellstress.cli import main

# 2 cells x 2 searchers x 2 seeds, small budget; s3's random runs find the hazard, s1's mostly do not
ARGS = ["--cells", "s1-scanner-width,s3-fence-gap", "--searchers", "random,mcts-commit", "--seeds", "2",
        "--budget", "40"]


@pytest.fixture(scope="module")
def ray_local():
    """A local Ray with 2 CPUs for this module; the campaign joins it instead of starting its own."""
    import ray  # in the test extra, so CI has it: this test must not skip

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="WARNING")
    yield ray
    ray.shutdown()


def _sorted_lines(out: Path) -> list[str]:
    return sorted((out / RUNS).read_text(encoding="utf-8").splitlines())


@pytest.fixture(scope="module")
def one_worker(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("w1")
    assert main(["campaign", *ARGS, "--workers", "1", "--out", str(out)]) == 0
    return out


def test_one_worker_gives_the_grid(one_worker):
    lines = _sorted_lines(one_worker)
    assert len(lines) == len(set(lines)) == 8
    assert any('"found":true' in ln for ln in lines) and any('"found":false' in ln for ln in lines)


def test_two_worker_processes_give_the_same_lines(one_worker, tmp_path):
    assert main(["campaign", *ARGS, "--workers", "2", "--out", str(tmp_path)]) == 0
    assert _sorted_lines(tmp_path) == _sorted_lines(one_worker)
    assert (tmp_path / "table.md").read_text() == (one_worker / "table.md").read_text()
    assert (tmp_path / "table.csv").read_text() == (one_worker / "table.csv").read_text()
    # the campaign report follows the plan's order, not the order in which runs finished
    assert (tmp_path / "report.html").read_bytes() == (one_worker / "report.html").read_bytes()
    assert (tmp_path / "discovery.png").read_bytes() == (one_worker / "discovery.png").read_bytes()


def test_campaign_writes_its_report(one_worker):
    from PIL import Image

    with Image.open(one_worker / "discovery.png") as im:
        im.load()
        assert im.width > 300 and im.height > 200
    html = (one_worker / "report.html").read_text(encoding="utf-8")
    assert "s1-scanner-width" in html and "mcts-commit" in html and "data:image/png;base64," in html


def test_ray_gives_the_same_lines(one_worker, tmp_path, ray_local):
    assert main(["campaign", *ARGS, "--backend", "ray", "--out", str(tmp_path)]) == 0
    assert _sorted_lines(tmp_path) == _sorted_lines(one_worker)
    assert (tmp_path / "table.csv").read_text() == (one_worker / "table.csv").read_text()
    assert ray_local.is_initialized()  # a cluster it joined is left running


def test_ray_with_a_limit_on_tasks_in_flight(one_worker, tmp_path, ray_local):
    plan = resolve(("s1-scanner-width", "s3-fence-gap"), ("random", "mcts-commit"), 2, 40)
    outcome = run_campaign(plan, tmp_path, Backend("ray", workers=1))
    assert (outcome.total, outcome.ran, outcome.done_before) == (8, 8, 0)
    assert _sorted_lines(tmp_path) == _sorted_lines(one_worker)


def test_everything_a_worker_gets_pickles():
    plan = resolve(("s1-scanner-width",), ("random", "mcts", "mcts-commit"), 2, 10)
    assert pickle.loads(pickle.dumps(plan)) == plan
    for spec in plan.runs():
        assert pickle.loads(pickle.dumps(spec)) == spec
    assert pickle.loads(pickle.dumps(execute)) is execute  # by reference: importable in any worker
    assert pickle.loads(pickle.dumps(Backend("ray", 2, "auto"))) == Backend("ray", 2, "auto")


def test_a_run_is_a_pure_function_of_its_spec():
    plan = resolve(("s3-fence-gap",), ("mcts",), 1, 30)
    (spec,) = plan.runs()
    assert execute(spec) == execute(pickle.loads(pickle.dumps(spec)))


def test_new_searchers_plug_in_without_campaign_changes(monkeypatch):
    """Searcher names and default options come from the searcher registry (``cellstress.searchers`` entry
    points): a registered plug-in runs in a campaign with no change to the campaign code."""
    from importlib.metadata import EntryPoint

    from cellstress.core import registry

    real = registry.entry_points

    class _Dist:  # the metadata of the plug-in's (imaginary) distribution
        metadata = {"Name": "lazy-plugin"}

    def entry_points(group):
        eps = list(real(group=group))
        if group == "cellstress.searchers":
            ep = EntryPoint("lazy-random", "campaign_lazy_plugin:Lazy", group)
            eps.append(type("EP", (), {"name": ep.name, "value": ep.value, "dist": _Dist()})())
        return eps

    monkeypatch.syspath_prepend(str(Path(__file__).parent))
    monkeypatch.setattr(registry, "entry_points", entry_points)
    registry.plugins.cache_clear()
    registry.load.cache_clear()
    try:
        plan = resolve(("s1-scanner-width",), ("lazy-random",), 1, 5)
        assert plan.searchers[0].params_dict == {"chunk": 8}
        rec = execute(plan.runs()[0])
        assert (rec["searcher"], rec["params"], rec["episodes"]) == ("lazy-random", {"chunk": 8}, 5)
    finally:
        registry.plugins.cache_clear()
        registry.load.cache_clear()


def test_a_worker_process_uses_one_numba_thread():
    """N workers on N cores must not each start a thread per core."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    import numba

    from cellstress.campaign.worker import init_worker

    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"), initializer=init_worker,
                             initargs=(1,)) as pool:
        assert pool.submit(numba.get_num_threads).result() == 1
