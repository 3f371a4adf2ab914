"""The shipped kernel cache (cellstress.core.jit): current, used on a fresh cache, and harmless when it cannot be."""

from __future__ import annotations

import ast
import json
import os
import pickle
import platform
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from cellstress.core import jit

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "cellstress"

# In a fresh interpreter: build a simulator and run what a first search runs, and count numba's compiles of
# cellstress's own functions (numba's helpers for typed lists etc. are not in the archive's scope).
CHILD = r"""
import json, sys
from cellstress.core import jit
from cellstress.core.jit import event
compiled = []
class L(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        if f.__module__.startswith("cellstress"):
            compiled.append(f.__qualname__)
    def on_end(self, ev):
        pass
event.register("numba:compile", L())
import numpy as np
from cellstress.sim.simulator import Simulator
s = Simulator("s3-fence-gap")
s.run_batch(np.zeros((4, 8), dtype=np.int64))
s.step(s.reset(), 0)
s.worker_paths(np.zeros((2, 8), dtype=np.int64))
from numba.core import config
print(json.dumps({"shipped": jit.USE_SHIPPED, "cpu": config.CPU_NAME, "compiled": compiled}))
"""


def child(tmp_path: Path, **env: str) -> dict:
    e = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), **env)
    for name in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        if name not in env:
            e.pop(name, None)
    p = subprocess.run([sys.executable, "-c", CHILD], env=e, capture_output=True, text=True, check=True,
                       timeout=900)
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_only_the_jit_module_imports_numba():
    """Otherwise numba could read its configuration before the CPU choice is made."""
    offenders = []
    for path in SRC.rglob("*.py"):
        if path == SRC / "core" / "jit.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n == "numba" or n.startswith("numba.") for n in names):
                offenders.append(f"{path.relative_to(SRC)}:{node.lineno}")
    assert offenders == []


def test_the_archive_is_current():
    """Fails after a change to a compiled module or to anything it imports: run scripts/build_kernel_cache.py."""
    p = subprocess.run([sys.executable, str(ROOT / "scripts" / "build_kernel_cache.py"), "--check"],
                       capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stdout + p.stderr


def test_the_archive_matches_this_installation():
    manifest = jit.read_manifest()
    assert manifest is not None and manifest["cpu"] == "x86-64-v2" and manifest["machine"] == "x86_64"
    assert manifest["python"] == jit.python_tag()
    if platform.machine().lower() in ("x86_64", "amd64"):  # elsewhere numba compiles, as it should
        assert jit.manifest_matches(manifest)
    assert jit.fresh_sources(manifest) == set(manifest["sources"])
    # every compiled module of the simulator is covered
    covered = set(manifest["indexes"].values())
    assert {"sim/kernels/step.py", "sim/kernels/batch.py", "sim/geometry.py", "human/reach.py"} <= covered


@pytest.mark.skipif(not jit.manifest_matches(jit.read_manifest()), reason="another numba or Python")
def test_a_fresh_cache_compiles_nothing_of_ours(tmp_path):
    doc = child(tmp_path)
    assert doc["shipped"] is True and doc["cpu"] == "x86-64-v2"
    assert doc["compiled"] == []
    assert any((tmp_path / "numba").rglob("*.nbi"))


def test_switched_off_it_touches_nothing(tmp_path):
    e = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), CELLSTRESS_SHIPPED_KERNELS="0")
    for name in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        e.pop(name, None)
    p = subprocess.run([sys.executable, "-c", "import os; from cellstress.sim import kernels; from cellstress.core "
                        "import jit; from numba.core import config; print(jit.USE_SHIPPED, config.CPU_NAME, "
                        "'NUMBA_CPU_NAME' in os.environ)"], env=e, capture_output=True, text=True, check=True)
    assert p.stdout.split() == ["False", "None", "False"]
    assert not any((tmp_path / "numba").rglob("*.nbi"))


def test_a_cpu_the_user_chose_is_kept(tmp_path):
    e = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), NUMBA_CPU_NAME="host")
    e.pop("NUMBA_CPU_FEATURES", None)
    p = subprocess.run([sys.executable, "-c", "from cellstress.core import jit; from numba.core import config;"
                        "print(jit.USE_SHIPPED, config.CPU_NAME)"], env=e, capture_output=True, text=True,
                       check=True)
    assert p.stdout.split() == ["False", "host"]


def test_seeding_keeps_entries_numba_wrote_and_adds_the_archives(tmp_path, monkeypatch):
    manifest = jit.read_manifest()
    member, source = next(iter(manifest["indexes"].items()))
    monkeypatch.setattr(jit, "cache_folder", lambda _source: tmp_path)
    with zipfile.ZipFile(jit.ARCHIVE) as z:
        stamp, shipped = jit.parse_index(z.read(member))
    name = Path(member).name
    base = name[: -len(".nbi")]
    # an index numba wrote for the same source, with one entry of its own in data file 1
    (tmp_path / f"{base}.1.nbc").write_bytes(b"numba's own")
    (tmp_path / name).write_bytes(jit.index_bytes(stamp, {("own", "key"): f"{base}.1.nbc"}))
    manifest = dict(manifest, indexes={member: source})
    added = jit.seed(manifest=manifest)
    assert added == len(shipped)
    _, overloads = jit.parse_index((tmp_path / name).read_bytes())
    assert overloads[("own", "key")] == f"{base}.1.nbc"
    assert (tmp_path / f"{base}.1.nbc").read_bytes() == b"numba's own"
    assert set(shipped) <= set(overloads) and len(set(overloads.values())) == len(overloads)
    assert jit.seed(manifest=manifest) == 0  # nothing left to add


def test_a_stale_index_is_replaced(tmp_path, monkeypatch):
    manifest = jit.read_manifest()
    member, source = next(iter(manifest["indexes"].items()))
    monkeypatch.setattr(jit, "cache_folder", lambda _source: tmp_path)
    name = Path(member).name
    (tmp_path / name).write_bytes(jit.index_bytes(b"another source", {("old",): "x.nbc"}))
    assert jit.seed(manifest=dict(manifest, indexes={member: source})) > 0
    stamp, overloads = jit.parse_index((tmp_path / name).read_bytes())
    assert stamp != b"another source" and ("old",) not in overloads


def test_a_damaged_archive_or_index_is_ignored(tmp_path):
    bad = tmp_path / "bad.zip"
    bad.write_bytes(b"not a zip")
    assert jit.read_manifest(bad) is None
    assert not jit.manifest_matches(None)
    assert jit.parse_index(b"garbage") is None
    assert jit.parse_index(pickle.dumps("0.0.0") + pickle.dumps((1, {}))) is None  # another numba's index
    other = tmp_path / "other.zip"
    with zipfile.ZipFile(other, "w") as z:
        z.writestr("manifest.json", json.dumps({"numba": "0.0.0", "python": jit.python_tag(), "sources": {}}))
    assert not jit.manifest_matches(jit.read_manifest(other))
    good = jit.read_manifest()
    assert not jit.manifest_matches(dict(good, machine="aarch64"))
    assert not jit.manifest_matches(dict(good, cpu_features=good["cpu_features"] + ["a-feature-no-cpu-has"]))
