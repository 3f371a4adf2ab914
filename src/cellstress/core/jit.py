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

Numba's cache files are pickles: loading one runs whatever code it names. So on every import, whether the
archive applies or not, this module first checks the folders numba would cache cellstress's functions in: a
folder another user could write into (or replace, through a folder above it) is never used; numba is pointed
at a folder only this user can write instead (``$CELLSTRESS_CACHE/numba-py311``, made 0700) and one warning line
says so (``guard_cache_folders``). The archive is seeded only into such a private folder, and a file already
there is compared with the archive's entry by SHA-256 (the manifest carries each entry's hash), never unpickled:
anything else there is replaced (``seed``). docs/security.md says what the cache trusts.

Every module of cellstress that uses numba imports it from here (a test checks), so this runs before numba
reads its configuration.
"""

from __future__ import annotations

import atexit
import hashlib
import json
import os
import pickle
import platform
import re
import shutil
import stat
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
from numba.core import caching, config, event, serialize  # noqa: E402,F401
from numba.core.cpu import CPUTargetOptions  # noqa: E402,F401
from numba.typed import List  # noqa: E402,F401


def cache_folder(source: Path) -> Path:
    """The folder numba caches ``source``'s functions in: numba's own locator decides, for a stand-in function
    of that file (numba makes the folder if it is missing)."""
    namespace: dict = {}
    exec(compile("def stand_in():\n    pass\n", str(source), "exec"), namespace)  # noqa: S102  (a fixed text)
    return Path(caching.CompileResultCacheImpl(namespace["stand_in"]).locator.get_cache_path())


def numba_folder(source: Path) -> Path:
    """``cache_folder``, without making it when numba's cache is a folder given by ``NUMBA_CACHE_DIR`` (we make it
    ourselves, for this user only)."""
    if config.CACHE_DIR:
        return Path(config.CACHE_DIR) / caching._CacheLocator.get_suitable_cache_subpath(str(source))
    return cache_folder(source)


def others_can_write(folder: Path) -> str | None:
    """Why a user other than this one (or root) could put a file into ``folder``, or replace it, in a few words;
    None when nobody can. The folder must be this user's and writable by nobody else; every folder above it (and
    above where its links lead) must be this user's or root's and writable by nobody else, unless it is sticky
    (as /tmp is: there others can add files but cannot rename ours). A folder not made yet counts as made by us
    (``private_folder`` makes it 0700)."""
    uid = os.geteuid()
    path = Path(os.path.abspath(folder))
    for chain in (path, Path(os.path.realpath(path))):
        for p in (chain, *chain.parents):
            try:
                st = os.lstat(p)
            except OSError:
                continue  # not there yet: made by us
            if stat.S_ISLNK(st.st_mode):
                continue  # the folder holding the link is checked next, where it leads in the resolved chain
            if st.st_uid not in (uid, 0) or (p == chain and st.st_uid != uid):
                return f"{p} belongs to another user"
            if st.st_mode & 0o022 and (p == chain or not st.st_mode & stat.S_ISVTX):
                return f"{p} is writable by {'every user' if st.st_mode & 0o002 else 'its group'}"
    return None


def private_folder(folder: Path) -> Path:
    """``folder``, each missing part made readable and writable by this user only (0700)."""
    missing = []
    p = Path(os.path.abspath(folder))
    while not os.path.lexists(p):
        missing.append(p)
        p = p.parent
    for m in reversed(missing):
        try:
            os.mkdir(m, 0o700)
        except FileExistsError:
            continue  # made meanwhile (by another process): others_can_write judges it
        os.chmod(m, 0o700)  # whatever the umask
    return folder


def private_cache_root() -> Path:
    """Where numba caches instead of a folder others can write: cellstress's own cache folder
    (``$CELLSTRESS_CACHE``, else ``~/.cache/cellstress``), or a fresh temporary folder if even that is shared."""
    base = Path(os.environ.get("CELLSTRESS_CACHE") or "~/.cache/cellstress").expanduser() / f"numba-{python_tag()}"
    try:
        private_folder(base)
        if others_can_write(base) is None:
            return base
    except OSError:
        pass
    tmp = Path(tempfile.mkdtemp(prefix="cellstress-numba-"))  # 0700 and new, so nobody else's
    owner = os.getpid()
    atexit.register(lambda: os.getpid() == owner and shutil.rmtree(tmp, ignore_errors=True))
    return tmp


def guard_cache_folders() -> str | None:
    """Keep numba from loading compiled code from a folder others can write (its index files are pickles:
    loading one runs whatever it holds). When a folder numba would cache cellstress's kernels in is such a
    folder, numba caches in ``private_cache_root()`` instead (for this process and those it starts); returns
    the one line that says so, or None when nothing was changed."""
    folders = []
    for d in sorted({f.parent for f in PACKAGE.rglob("*.py")}):
        try:
            folders.append(numba_folder(d / "__init__.py") if (d / "__init__.py").is_file() else None)
        except (OSError, RuntimeError):
            continue  # numba finds no folder it can write there: it caches nothing, loads nothing
    for folder in filter(None, folders):
        reason = others_can_write(folder)
        if reason is not None:
            root = private_cache_root()
            config.CACHE_DIR = str(root)
            os.environ["NUMBA_CACHE_DIR"] = str(root)  # spawned workers inherit it
            return (f"warning: numba's cache folder {folder} is not safe ({reason}); cellstress loads no compiled "
                    f"code from it and caches its kernels in {root}, which only you can write")
    return None


def _file_hash(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def parse_index(data: bytes) -> tuple[object, dict] | None:
    """(source stamp, overloads) of a numba index file's bytes if this numba version wrote it, else None. Only
    for the archive's own entries: unpickling runs code, and a cached file is compared by hash, never parsed."""
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


def entries_of(member: str, members: set[str]) -> list[str]:
    """An index's data files in the archive (``NAME.N.nbc`` beside ``NAME.nbi``), then the index itself."""
    base = member[: -len(".nbi")]
    data = sorted(m for m in members if m.startswith(base + ".") and re.fullmatch(r"\d+\.nbc", m[len(base) + 1:]))
    return [*data, member]


def seed(archive: Path = ARCHIVE, manifest: dict | None = None) -> int:
    """Copy the archive's cache entries where numba will look for them; returns how many files it wrote.

    An entry goes only into a folder this user owns and nobody else can write (made 0700 if missing). A file
    already there is compared by its SHA-256 with the archive's, never unpickled: the same bytes stay, any other
    (numba's own index for other signatures, a stale one, one planted) is replaced. The manifest of an archive
    built since issue 29 carries each entry's hash (``files``); for an older archive the hash is taken from the
    archive's own bytes, which ship with the package. Files are written whole and renamed into place (the data
    files before the index that names them), so processes seeding at once never see half a file."""
    manifest = manifest if manifest is not None else read_manifest(archive)
    if not manifest:
        return 0
    fresh = fresh_sources(manifest)
    closures = manifest.get("closures", {})
    listed = manifest.get("files")
    written = 0
    with zipfile.ZipFile(archive) as z:
        members = set(z.namelist())

        def shipped_hash(m: str) -> str:
            return listed[m] if listed else hashlib.sha256(z.read(m)).hexdigest()

        for member, source in manifest["indexes"].items():
            if not set(closures.get(source, [source])) <= fresh:
                continue  # this module or something it imports was edited since the archive was built
            folder = private_folder(numba_folder(PACKAGE / source))
            if others_can_write(folder) is not None:
                continue  # guard_cache_folders has moved numba elsewhere; never seed a shared folder
            todo = [m for m in entries_of(member, members)
                    if _file_hash(folder / PurePosixPath(m).name) != shipped_hash(m)]
            blobs = {m: z.read(m) for m in todo}
            if listed and any(hashlib.sha256(b).hexdigest() != listed[m] for m, b in blobs.items()):
                continue  # a damaged archive: this function compiles as usual
            if todo and todo[-1] == member:  # no process may read the old index while its data files change
                (folder / PurePosixPath(member).name).unlink(missing_ok=True)
            for m in todo:
                _write_atomically(folder / PurePosixPath(m).name, blobs[m])
                written += 1
    return written


GUARD_NOTE = guard_cache_folders()
if GUARD_NOTE is not None:
    print(GUARD_NOTE, file=sys.stderr)  # once per process: the workers it starts inherit the safe folder

if USE_SHIPPED:
    try:
        seed(manifest=_manifest)
    except (OSError, KeyError, zipfile.BadZipFile):
        pass  # an unwritable cache folder or a damaged archive: numba compiles as usual
