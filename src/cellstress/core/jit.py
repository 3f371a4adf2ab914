"""numba, set up once for every compiled module: a portable CPU target and the kernels compiled ahead.

A fresh installation would otherwise spend about a minute compiling the simulator before its first search
(numba compiles on first call, then loads from its on-disk cache). cellstress therefore ships that cache:
``kernel_cache.zip`` beside this file holds numba's cache files for every ``cache=True`` function, built by
``scripts/build_kernel_cache.py`` for one numba version and one Python, for the x86-64-v2 CPU level (numba's
cache is keyed by CPU model; x86-64-v2, SSE4.2 and POPCNT, runs on every x86-64 processor since 2009; the plain
generic level lacks SSE4.1's rounding instructions, which made the reach field's rasterising 2.7 times
slower). On import, when this installation matches the archive (same numba, same Python, an x86-64 machine
with those instructions), this module

1. selects that CPU target for numba (``NUMBA_CPU_NAME``), unless the user chose a CPU, and
2. copies the archive's entries into the folder numba itself would cache each source file in (numba picks it:
   ``NUMBA_CACHE_DIR``, else ``__pycache__`` beside the source when writable, else the user-wide cache), so
   numba finds them as if it had compiled them there.

When the installation differs (another numba or Python, another processor, numba imported before cellstress,
a CPU the user chose, or ``CELLSTRESS_SHIPPED_KERNELS=0``) nothing is touched and numba compiles as usual. A
module is seeded only if it and every cellstress file it imports are byte for byte those the archive was built
from: numba's own freshness check reads only the function's own file, so an edited helper inlined from another
file, or a changed layout constant, would go unnoticed.

Every module of cellstress that uses numba imports it from here (a test checks), so this runs before numba
reads its configuration.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import platform
import sys
import tempfile
import zipfile
from importlib import metadata
from pathlib import Path, PurePosixPath

PACKAGE = Path(__file__).resolve().parent.parent
ARCHIVE = Path(__file__).with_name("kernel_cache.zip")
MANIFEST = "manifest.json"
SWITCH = "CELLSTRESS_SHIPPED_KERNELS"


def python_tag() -> str:
    """The tag numba puts in its cache file names (``py311``)."""
    return f"py{sys.version_info.major}{sys.version_info.minor}"


def source_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_manifest(archive: Path = ARCHIVE) -> dict | None:
    try:
        with zipfile.ZipFile(archive) as z:
            return json.loads(z.read(MANIFEST))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


def manifest_matches(manifest: dict | None) -> bool:
    """Whether the archive was built for this numba, this Python and a CPU level this machine has."""
    if not manifest:
        return False
    try:
        if metadata.version("numba") != manifest.get("numba") or manifest.get("python") != python_tag():
            return False
    except metadata.PackageNotFoundError:
        return False
    if platform.machine().lower() not in ("x86_64", "amd64") or manifest.get("machine") != "x86_64":
        return False
    from llvmlite import binding  # noqa: PLC0415  (only when the archive can apply; it does not read numba's config)

    have = binding.get_host_cpu_features()
    return all(have.get(feature, False) for feature in manifest.get("cpu_features", ["?"]))


def fresh_sources(manifest: dict) -> set[str]:
    """The package's files (relative paths) whose bytes are those the archive was built from."""
    fresh = set()
    for rel, digest in manifest.get("sources", {}).items():
        path = PACKAGE / rel
        if path.is_file() and source_digest(path) == digest:
            fresh.add(rel)
    return fresh


def _choose_cpu(cpu: str) -> bool:
    """Select the archive's CPU before numba reads its configuration; False when that is no longer possible or
    the user has chosen another."""
    if "numba" in sys.modules:
        from numba.core import config  # noqa: PLC0415  (numba is already loaded: reading it costs nothing)

        return config.CPU_NAME == cpu and not config.CPU_FEATURES
    if "NUMBA_CPU_NAME" in os.environ or "NUMBA_CPU_FEATURES" in os.environ:
        return os.environ.get("NUMBA_CPU_NAME") == cpu and not os.environ.get("NUMBA_CPU_FEATURES")
    os.environ["NUMBA_CPU_NAME"] = cpu
    os.environ["NUMBA_CPU_FEATURES"] = ""  # the CPU level's own features, none of the host's beyond them
    return True


_manifest = read_manifest() if os.environ.get(SWITCH, "1") != "0" else None
USE_SHIPPED = manifest_matches(_manifest) and _choose_cpu(_manifest["cpu"])

import numba  # noqa: E402  (after the CPU choice above)
from numba import njit, prange  # noqa: E402,F401  (re-exported: cellstress's compiled modules import them here)
from numba.core import caching, event, serialize  # noqa: E402,F401
from numba.core.cpu import CPUTargetOptions  # noqa: E402,F401
from numba.typed import List  # noqa: E402,F401


def cache_folder(source: Path) -> Path:
    """The folder numba caches ``source``'s functions in: numba's own locator decides, for a stand-in function
    of that file."""
    namespace: dict = {}
    exec(compile("def stand_in():\n    pass\n", str(source), "exec"), namespace)  # noqa: S102  (a fixed text)
    return Path(caching.CompileResultCacheImpl(namespace["stand_in"]).locator.get_cache_path())


def parse_index(data: bytes) -> tuple[object, dict] | None:
    """(source stamp, overloads) of a numba index file's bytes if this numba version wrote it, else None."""
    try:
        version_end = len(pickle.dumps(numba.__version__, protocol=-1))
        if pickle.loads(data[:version_end]) != numba.__version__:
            return None
        stamp, overloads = pickle.loads(data[version_end:])
        return stamp, dict(overloads)
    except (EOFError, pickle.UnpicklingError, ValueError, TypeError, AttributeError, ImportError):
        return None


def index_bytes(stamp: object, overloads: dict) -> bytes:
    """An index file's bytes as numba writes them: its version, then the stamp and the overloads."""
    return pickle.dumps(numba.__version__, protocol=-1) + serialize.dumps((stamp, overloads))


def _write_atomically(path: Path, data: bytes) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def seed(archive: Path = ARCHIVE, manifest: dict | None = None) -> int:
    """Copy the archive's cache entries where numba will look for them; returns how many entries it added.

    An index numba already keeps for the same source gains the archive's entries it lacks (its own, e.g. for
    other signatures, stay); a missing or stale one is replaced. Files are written whole and renamed into
    place, so processes seeding at once (campaign workers) never see half a file."""
    manifest = manifest if manifest is not None else read_manifest(archive)
    if not manifest:
        return 0
    fresh = fresh_sources(manifest)
    closures = manifest.get("closures", {})
    added = 0
    with zipfile.ZipFile(archive) as z:
        for member, source in manifest["indexes"].items():
            if not set(closures.get(source, [source])) <= fresh:
                continue  # this module or something it imports was edited since the archive was built
            shipped = parse_index(z.read(member))
            if shipped is None:
                continue
            folder = cache_folder(PACKAGE / source)
            target = folder / PurePosixPath(member).name
            try:
                current = parse_index(target.read_bytes())
            except OSError:
                current = None
            stamp, overloads = current if current is not None and current[0] == shipped[0] else (shipped[0], {})
            missing = [key for key in shipped[1] if key not in overloads]
            if not missing:
                continue
            used = set(overloads.values())
            base = PurePosixPath(member).name[: -len(".nbi")]
            number = 0
            for key in missing:
                number += 1
                while f"{base}.{number}.nbc" in used:
                    number += 1
                name = f"{base}.{number}.nbc"
                used.add(name)
                _write_atomically(folder / name, z.read(str(PurePosixPath(member).parent / shipped[1][key])))
                overloads[key] = name
                added += 1
            _write_atomically(target, index_bytes(stamp, overloads))
    return added


if USE_SHIPPED:
    try:
        seed(manifest=_manifest)
    except (OSError, KeyError, zipfile.BadZipFile):
        pass  # an unwritable cache folder or a damaged archive: numba compiles as usual
