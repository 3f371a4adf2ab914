"""The shipped kernel cache (cellstress.core.jit): current, used on a fresh cache, and harmless when it cannot be."""

from __future__ import annotations

import ast
import hashlib
import json
import os
import pickle
import platform
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from cellstress.core import jit
from cellstress.core.jit import caching, numba

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "cellstress"

# In a fresh interpreter: build a simulator and run what a first search and a small verify tree run, and count
# numba's compiles of cellstress's own functions (numba's helpers for typed lists etc. are not in the archive's
# scope).
CHILD = r"""
import json, sys
from cellstress.core import jit
from cellstress.core.jit import caching, numba
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
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.tree import decide
assert decide(s, 3, Bounds(s, horizon=3)).pruned_states["distance"]  # a last layer reached (verifier.last_action)
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


class Planted:
    """A pickle that runs code when unpickled: it makes the folder ``marker``."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (os.mkdir, (str(self.marker),))


def _one_index(manifest: dict) -> tuple[dict, str, list[str]]:
    """The archive's manifest cut to its first index, with no source to be fresh (so the test does not depend on
    the archive being current), the index's member name and its entries (data files, then the index)."""
    member, source = next(iter(manifest["indexes"].items()))
    with zipfile.ZipFile(jit.ARCHIVE) as z:
        entries = jit.entries_of(member, set(z.namelist()))
    return dict(manifest, indexes={member: source}, closures={source: []}), member, entries


def _archive_bytes(member: str) -> bytes:
    with zipfile.ZipFile(jit.ARCHIVE) as z:
        return z.read(member)


@pytest.fixture
def private(tmp_path, monkeypatch) -> Path:
    folder = tmp_path / "cache"
    folder.mkdir(mode=0o700)
    monkeypatch.setattr(jit, "numba_folder", lambda _source: folder)
    return folder


@pytest.mark.parametrize("hashes", ["in the manifest", "from the archive"])
def test_seeding_compares_by_hash_and_never_unpickles_what_is_there(tmp_path, private, hashes):
    """Issue 29: a cached index is compared with the archive's by SHA-256 and replaced, never unpickled. An
    archive built before per-entry hashes (no ``files``) is compared with its own bytes."""
    manifest, member, entries = _one_index(jit.read_manifest())
    if hashes == "in the manifest":
        manifest["files"] = {m: hashlib.sha256(_archive_bytes(m)).hexdigest() for m in entries}
    else:
        manifest.pop("files", None)
    marker = tmp_path / "pwned"
    bad = pickle.dumps(numba.__version__, protocol=-1) + pickle.dumps(Planted(marker))
    for m in entries:
        (private / Path(m).name).write_bytes(bad)
    assert jit.seed(manifest=manifest) == len(entries)
    assert not marker.exists()
    for m in entries:
        assert (private / Path(m).name).read_bytes() == _archive_bytes(m)
    assert jit.seed(manifest=manifest) == 0  # the same bytes: nothing to write
    assert jit.parse_index((private / Path(member).name).read_bytes()) is not None


def test_an_index_numba_wrote_for_other_signatures_is_replaced(private):
    manifest, member, entries = _one_index(jit.read_manifest())
    stamp, shipped = jit.parse_index(_archive_bytes(member))
    name = Path(member).name
    (private / name).write_bytes(jit.index_bytes(stamp, {("own", "key"): "x.99.nbc", **shipped}))
    assert jit.seed(manifest=manifest) >= 1
    assert (private / name).read_bytes() == _archive_bytes(member)


def test_a_damaged_entry_is_not_seeded(private):
    manifest, member, entries = _one_index(jit.read_manifest())
    manifest["files"] = {m: hashlib.sha256(_archive_bytes(m)).hexdigest() for m in entries}
    manifest["files"][entries[0]] = "0" * 64
    assert jit.seed(manifest=manifest) == 0
    assert list(private.iterdir()) == []


def test_a_shared_folder_is_never_seeded(tmp_path, monkeypatch):
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    monkeypatch.setattr(jit, "numba_folder", lambda _source: shared)
    manifest, _, _ = _one_index(jit.read_manifest())
    assert jit.seed(manifest=manifest) == 0
    assert list(shared.iterdir()) == []


def test_a_missing_folder_is_made_for_this_user_only(tmp_path, monkeypatch):
    folder = tmp_path / "a" / "b"
    monkeypatch.setattr(jit, "numba_folder", lambda _source: folder)
    old = os.umask(0o002)
    try:
        manifest, _, entries = _one_index(jit.read_manifest())
        assert jit.seed(manifest=manifest) == len(entries)
    finally:
        os.umask(old)
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700 and stat.S_IMODE(folder.parent.stat().st_mode) == 0o700


def test_who_else_can_write_a_folder(tmp_path):
    own = tmp_path / "own"
    own.mkdir(mode=0o700)
    assert jit.others_can_write(own) is None
    assert jit.others_can_write(own / "not" / "made" / "yet") is None
    own.chmod(0o770)
    assert jit.others_can_write(own) == f"{own} is writable by its group"
    own.chmod(0o707)
    assert jit.others_can_write(own) == f"{own} is writable by every user"
    sticky = tmp_path / "tmp"
    sticky.mkdir()
    sticky.chmod(0o1777)  # as /tmp: others add files but cannot move ours
    (sticky / "mine").mkdir(mode=0o700)
    assert jit.others_can_write(sticky / "mine") is None
    assert jit.others_can_write(sticky) is not None  # but the sticky folder itself takes anyone's files
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    (shared / "mine").mkdir(mode=0o700)
    assert jit.others_can_write(shared / "mine") == f"{shared} is writable by every user"
    (tmp_path / "link").symlink_to(shared / "mine")  # a link leads into the shared folder: judged where it leads
    assert jit.others_can_write(tmp_path / "link") == f"{shared} is writable by every user"


@pytest.mark.skipif(os.geteuid() != 0, reason="only root can give a folder to another user")
def test_a_folder_of_another_user(tmp_path):
    other = tmp_path / "other"
    other.mkdir(mode=0o700)
    os.chown(other, 65534, 65534)
    assert jit.others_can_write(other) == f"{other} belongs to another user"


PLANTED_CHILD = r"""
import numpy as np
from cellstress.sim import geometry
from cellstress.core import jit
from cellstress.core.jit import caching, numba
from numba.core import config
verts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
print(geometry.point_in_polygon(0.2, 0.2, verts, 0, 3), config.CACHE_DIR)
"""


def test_a_pickle_planted_in_a_shared_cache_is_never_loaded(tmp_path):
    """Issue 29: an index planted in a world-writable NUMBA_CACHE_DIR ran its code on import. Now numba is kept
    from that folder (one warning line) and caches in a folder only this user can write."""
    from cellstress.sim import geometry

    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    marker = tmp_path / "pwned"
    impl = caching.CompileResultCacheImpl(geometry.point_in_polygon.py_func)
    folder = shared / caching._CacheLocator.get_suitable_cache_subpath(geometry.__file__)
    folder.mkdir()
    (folder / f"{impl.filename_base}.nbi").write_bytes(
        pickle.dumps(numba.__version__, protocol=-1) + pickle.dumps(Planted(marker)))
    e = dict(os.environ, NUMBA_CACHE_DIR=str(shared), CELLSTRESS_CACHE=str(tmp_path / "mine"))
    p = subprocess.run([sys.executable, "-c", PLANTED_CHILD], env=e, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    assert not marker.exists()
    mine = tmp_path / "mine" / f"numba-{jit.python_tag()}"
    assert p.stdout.split() == ["True", str(mine)]
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: numba's cache folder") and str(shared) in lines[0]
    assert f"{shared} is writable by every user" in lines[0] and str(mine) in lines[0]
    assert stat.S_IMODE(mine.stat().st_mode) == 0o700


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


def test_the_build_script_records_each_entrys_hash(tmp_path, monkeypatch):
    """scripts/build_kernel_cache.py packs a manifest whose ``files`` are the sha256 of every packed entry, in
    the format jit.seed reads (issue 29)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("build_kernel_cache", ROOT / "scripts" / "build_kernel_cache.py")
    build = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build)
    monkeypatch.setattr(build, "ARCHIVE", tmp_path / "kernel_cache.zip")
    cache = tmp_path / "numba"
    folder = cache / caching._CacheLocator.get_suitable_cache_subpath(str(SRC / "sim" / "geometry.py"))
    folder.mkdir(parents=True)
    (folder / "geometry.f-1.py311.nbi").write_bytes(b"index")
    (folder / "geometry.f-1.py311.1.nbc").write_bytes(b"data")
    manifest = build.pack(cache)
    assert manifest["files"] == {"sim/geometry.f-1.py311.nbi": hashlib.sha256(b"index").hexdigest(),
                                 "sim/geometry.f-1.py311.1.nbc": hashlib.sha256(b"data").hexdigest()}
    assert jit.read_manifest(tmp_path / "kernel_cache.zip")["files"] == manifest["files"]
    with zipfile.ZipFile(tmp_path / "kernel_cache.zip") as z:
        assert jit.entries_of("sim/geometry.f-1.py311.nbi", set(z.namelist())) == [
            "sim/geometry.f-1.py311.1.nbc", "sim/geometry.f-1.py311.nbi"]
