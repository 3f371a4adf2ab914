"""Build src/cellstress/core/kernel_cache.zip: numba's cache of every compiled function, shipped with the package.

    python scripts/build_kernel_cache.py [--check]

Runs the commands below in fresh interpreters with an empty NUMBA_CACHE_DIR, numba's CPU set to the x86-64-v2
level and the shipped cache switched off, so numba compiles every kernel a user's commands reach and writes its
cache files there; then packs them with a manifest (numba version, Python, the sha256 of every source file each
compiled module imports within cellstress, transitively: a kernel's code can depend on nothing else, and the sha256
of every cache file packed, which a cached copy is compared with before numba may read it). Run it
after changing any compiled module or what it imports; tests/core/test_jit.py fails until then. ``--check``
only says whether the archive is current (exit 1 if not). See cellstress.core.jit for how it is used.
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "src" / "cellstress"
ARCHIVE = PACKAGE / "core" / "kernel_cache.zip"
CPU = "x86-64-v2"
# What x86-64-v2 requires (x86-64 itself, then CMPXCHG16B, LAHF/SAHF, POPCNT, SSE3, SSE4.1, SSE4.2, SSSE3), as
# llvmlite names the host's features: the archive is used only on a machine that has them all.
CPU_FEATURES = ["cmov", "cx8", "fxsr", "mmx", "sse", "sse2", "cx16", "sahf", "popcnt", "sse3", "sse4.1", "sse4.2",
                "ssse3"]

# Every entry point of the compiled code: the searchers (one run each; evolve's lookahead score), replay and the
# report (scene), check and show (the plane and reach analyses), verify (its expansion kernel), the curtain probe
# ("@" runs a script of this repository) and a cell of each kind of safeguard and robot, in case a cell's arrays
# ever give a kernel another signature.
COMMANDS = [
    ["search", "s3-fence-gap", "--searcher", "plan", "--budget", "40", "--seed", "0", "--out", "{out}/plan"],
    ["report", "{out}/plan/result.json"],
    ["replay", "{out}/plan/result.json"],
    ["search", "s1-scanner-width", "--searcher", "random", "--budget", "50", "--seed", "0", "--out", "{out}/r"],
    ["search", "s2-elbow-intrusion", "--searcher", "mcts", "--budget", "30", "--seed", "0", "--out", "{out}/m"],
    ["search", "baseline", "--searcher", "mcts-commit", "--budget", "30", "--seed", "0", "--out", "{out}/mc"],
    ["search", "all-flaws", "--searcher", "evolve", "--budget", "60", "--seed", "0", "--distinct", "--until", "budget",
     "--out", "{out}/e"],
    ["search", "baseline", "--searcher", "random", "--budget", "20", "--seed", "0", "--criterion", "iso15066",
     "--out", "{out}/iso"],
    ["search", "palletizing", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/p"],
    ["search", "restart-auto", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/ra"],
    ["search", "warning-field-short", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/w"],
    ["search", "mat-short", "--searcher", "random", "--budget", "20", "--seed", "0", "--out", "{out}/mat"],
    ["search", "door-unlocked", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/door"],
    ["search", "muting-long", "--searcher", "random", "--budget", "20", "--seed", "0", "--out", "{out}/mute"],
    ["search", "two-robots", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/two"],
    ["verify", "two-robots", "--horizon", "2", "--out", "{out}/v2"],
    ["search", "ssm-latency", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/ssm"],
    # the articulated worker: plan measures its capsules (kernels.pose_capsules), the report draws them
    ["search", "reach-over", "--searcher", "plan", "--budget", "20", "--seed", "0", "--out", "{out}/arms"],
    ["check", "reach-over"],
    ["simulate", "s3-fence-gap", "--actions", "walk+upright,walk+upright"],
    ["check", "s3-fence-gap"],
    ["show", "s3-fence-gap", "--out", "{out}/show.png"],
    ["verify", "baseline", "--horizon", "2", "--out", "{out}/v"],
    # a last layer that is reached (verifier.last_action, expand_pairs): baseline's and two-robots' trees end after
    # their first action
    ["verify", "s3-fence-gap", "--horizon", "3", "--phases", "cell", "--out", "{out}/v3"],
    ["search", "s2-elbow-intrusion", "--searcher", "evolve", "--budget", "30", "--seed", "0", "--set", "score=all",
     "--out", "{out}/la"],
    ["@scripts/curtain_probe.py", "s2-elbow-intrusion", "--step", "0.25"],  # analysis.probe
    # the 5 ms cross-check of the swept test (kernels.dense), which tests/sim/test_sweep.py runs on every CI
    ["@benchmarks/sweep_check.py", "--cells", "s3-fence-gap", "--episodes", "20"],
]


def module_file(name: str) -> Path | None:
    """The file of a cellstress module name, or None outside the package."""
    if name != "cellstress" and not name.startswith("cellstress."):
        return None
    parts = name.split(".")[1:]
    base = PACKAGE.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def module_level(body: list[ast.stmt]):
    """The statements a module runs on import: its top level, into if/try blocks but not ``if TYPE_CHECKING``
    (functions, whose imports run later, cannot change what a kernel compiled into)."""
    for node in body:
        if isinstance(node, ast.If):
            test = node.test
            if (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
                    isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"):
                yield from module_level(node.orelse)
                continue
            yield from module_level(node.body)
            yield from module_level(node.orelse)
        elif isinstance(node, ast.Try):
            for block in (node.body, node.orelse, node.finalbody, *[h.body for h in node.handlers]):
                yield from module_level(block)
        else:
            yield node


def imports_of(path: Path) -> set[Path]:
    """The cellstress files importing ``path`` runs: its module-level imports and the packages on the way."""
    found: set[Path] = set()
    for node in module_level(ast.parse(path.read_text()).body):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        for name in names:
            parts = name.split(".")
            for i in range(1, len(parts) + 1):
                f = module_file(".".join(parts[:i]))
                if f is not None:
                    found.add(f)
    return found


def closure(path: Path) -> set[Path]:
    seen, todo = {path}, [path]
    while todo:
        for f in imports_of(todo.pop()):
            if f not in seen:
                seen.add(f)
                todo.append(f)
    return seen


def run_commands(cache: Path, out: Path) -> None:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), NUMBA_CPU_NAME=CPU, NUMBA_CPU_FEATURES="",
               CELLSTRESS_SHIPPED_KERNELS="0", CELLSTRESS_CACHE=str(out / "reach-cache"), MPLBACKEND="Agg")
    for args in COMMANDS:
        args = [a.format(out=out) for a in args]
        print(" ".join(args), flush=True)
        head = [str(ROOT / args.pop(0)[1:])] if args[0].startswith("@") else ["-m", "cellstress.cli"]
        p = subprocess.run([sys.executable, *head, *args], env=env, capture_output=True, text=True, check=False)
        if p.returncode not in (0, 1):  # 1: a hazard was found, as intended for most of these cells
            sys.exit(f"failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-3000:]}")


def pack(cache: Path) -> dict:
    import numba  # noqa: PLC0415  (the script's own interpreter: only to name its version)
    from numba.core.caching import _CacheLocator  # noqa: PLC0415

    folders = {}
    for d in sorted({p.parent for p in PACKAGE.rglob("*.py")}):
        folders[_CacheLocator.get_suitable_cache_subpath(str(d / "x.py"))] = d
    manifest: dict = {"numba": numba.__version__, "python": f"py{sys.version_info.major}{sys.version_info.minor}",
                      "machine": "x86_64", "cpu": CPU, "cpu_features": CPU_FEATURES,
                      "indexes": {}, "closures": {}, "sources": {}}
    files: dict[str, Path] = {}
    for folder in sorted(cache.iterdir()):
        src_dir = folders.get(folder.name)
        if src_dir is None:
            continue  # a function outside cellstress
        for index in sorted(folder.glob("*.nbi")):
            source = src_dir / (index.name.split(".")[0] + ".py")
            rel_dir = src_dir.relative_to(PACKAGE).as_posix()
            member = f"{rel_dir}/{index.name}"
            rel_source = source.relative_to(PACKAGE).as_posix()
            manifest["indexes"][member] = rel_source
            files[member] = index
            for data in folder.glob(index.name[: -len(".nbi")] + ".*.nbc"):
                files[f"{rel_dir}/{data.name}"] = data
            deps = sorted(f.relative_to(PACKAGE).as_posix() for f in closure(source))
            manifest["closures"][rel_source] = deps
            for rel in deps:
                manifest["sources"][rel] = hashlib.sha256((PACKAGE / rel).read_bytes()).hexdigest()
    # each entry's sha256: jit.seed compares a file already in a cache folder with it, and never unpickles one
    manifest["files"] = {member: hashlib.sha256(files[member].read_bytes()).hexdigest() for member in sorted(files)}
    tmp = ARCHIVE.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        z.writestr("manifest.json", json.dumps(manifest, indent=1, sort_keys=True))
        for member in sorted(files):
            z.write(files[member], member)
    os.replace(tmp, ARCHIVE)
    return manifest


def stale() -> list[str]:
    """Source files whose bytes differ from the archive's manifest (or 'archive' if there is none)."""
    try:
        with zipfile.ZipFile(ARCHIVE) as z:
            manifest = json.loads(z.read("manifest.json"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return ["archive"]
    out = []
    for rel, digest in manifest["sources"].items():
        p = PACKAGE / rel
        if not p.is_file() or hashlib.sha256(p.read_bytes()).hexdigest() != digest:
            out.append(rel)
    for rel_source, deps in manifest["closures"].items():
        now = sorted(f.relative_to(PACKAGE).as_posix() for f in closure(PACKAGE / rel_source))
        if now != deps:
            out.append(f"{rel_source} (imports changed)")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="only say whether the archive is current")
    a = ap.parse_args()
    if a.check:
        bad = stale()
        print("current" if not bad else "stale: " + ", ".join(bad))
        sys.exit(1 if bad else 0)
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
        run_commands(Path(cache), Path(out))
        m = pack(Path(cache))
    print(f"{ARCHIVE.relative_to(ROOT)}: {len(m['indexes'])} indexes, {len(m['sources'])} source files, "
          f"{ARCHIVE.stat().st_size / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
