"""Hostile inputs: cell files, result files, options and names that other people might send.

Each case runs the command line in a process of its own (forked from one that has imported cellstress), under a
time limit and an address-space limit, in a working folder of its own. Each asserts the exit code (2 for a bad
input, with exactly one line on stderr that starts with ``error:``; 1 for a result file whose claims do not hold;
0 for a strange but valid input), no traceback, nothing created or changed outside the output folder, and text
escaped for where it lands (terminal, HTML, CSV, Markdown).

The cases are samples of kinds (files that are not files, bombs, deep nesting, numbers out of range, lax
types, forged results, names that try to become paths or markup); the code under test handles the kind, not
the sample. All cases run once per session, two at a time, in a fixture (``ran``: one xdist worker plays them,
the others read its outcome); each test then checks one case.
"""

from __future__ import annotations

import copy
import fcntl
import json
import math
import os
import pickle
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from queue import Queue

import pytest
import yaml

from cellstress.cli import main

TIME_LIMIT = 300  # s per process: generous for a loaded CI machine; a hang is what it catches
MEMORY_LIMIT = 6 * 2**30  # bytes of address space per process
# One process per input: it runs each command that reads the input in turn, each with its own stdout and
# stderr, and reports exit codes (a crash of the command itself shows as a traceback in its stderr).
# The process's file descriptor 2 is captured too, command by command: a C library (the URDF parser, numba)
# writes there past Python's sys.stderr, and a user sees those lines.
CHILD = f"""
import contextlib, io, json, os, resource, sys, tempfile, traceback
resource.setrlimit(resource.RLIMIT_AS, ({MEMORY_LIMIT}, {MEMORY_LIMIT}))
from cellstress.cli import main
done = []
saved = os.dup(2)
for argv in json.load(open(sys.argv[1])):
    out, err = io.StringIO(), io.StringIO()
    fd2 = tempfile.TemporaryFile()
    os.dup2(fd2.fileno(), 2)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:
                code = exc.code
            except BaseException:
                traceback.print_exc()
                code = -1
    finally:
        os.dup2(saved, 2)
    fd2.seek(0)
    raw = fd2.read().decode("utf-8", "replace")
    done.append({{"code": code, "out": out.getvalue(), "err": raw + err.getvalue()}})
json.dump(done, open(sys.argv[2], "w"))
"""
# Each group's process is forked from one that has already imported cellstress and what its commands import (a
# fresh interpreter spends seconds on those imports; 190 groups did): it is still a process of its own, in its own
# folder, under the same limits; it runs CHILD. Nothing runs a kernel before the fork (numba's thread pools are not
# fork-safe); each child loads its kernels as a fresh process does.
FORKS = f"""
import importlib, json, os, pkgutil, signal, sys, time
import cellstress
for m in pkgutil.walk_packages(cellstress.__path__, "cellstress."):
    if not m.name.endswith("__main__"):
        try:
            importlib.import_module(m.name)
        except Exception:
            pass
child = compile({CHILD!r}, "<child>", "exec")
for line in sys.stdin:
    req = json.loads(line)
    pid = os.fork()
    if pid == 0:
        status = 1
        try:
            os.chdir(req["cwd"])
            null = os.open(os.devnull, os.O_RDWR)
            os.dup2(null, 0)
            os.dup2(null, 1)  # (fd 1 is the answer pipe)
            sys.argv = ["-c", req["commands"], req["report"]]
            exec(child, {{"__name__": "__main__"}})
            status = 0
        finally:
            os._exit(status)
    deadline, status = time.monotonic() + {TIME_LIMIT}, None
    while True:
        done, raw = os.waitpid(pid, os.WNOHANG)
        if done:
            status = os.waitstatus_to_exitcode(raw)
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            break
        time.sleep(0.02)
    print(json.dumps(status), flush=True)
"""
CELL, RESULT = "in/cell.yaml", "out/result.json"
SEARCH = ("search", CELL, "--budget", "2", "--searcher", "random", "--out", "out", "--no-report")
CELL_COMMANDS = {
    "check": ("check", CELL),
    "search": SEARCH,
    "simulate": ("simulate", CELL, "--actions", "walk+upright"),
    "show": ("show", CELL, "--out", "out/cell.png"),
    "campaign": ("campaign", "--cells", CELL, "--searchers", "random", "--seeds", "1", "--budget", "2",
                 "--workers", "1", "--out", "out"),
    "verify": ("verify", CELL, "--horizon", "1", "--phases", "cell", "--workers", "1", "--out", "out"),
}


@dataclass(frozen=True)
class Case:
    id: str
    argv: tuple[str, ...]
    code: int = 2
    says: tuple[str, ...] = ()  # words of the error line (exit 2), of a MISMATCH line (exit 1)
    cell: Callable[[dict], object] | None = None  # a change of the baseline, written to in/cell.yaml
    cell_bytes: bytes | None = None  # or the file's bytes
    result: Callable[[dict], object] | None = None  # a change of a real result file, written to out/
    result_bytes: bytes | None = None
    setup: Callable[[Path], object] | None = None  # anything else, in the case's folder
    group: str = ""  # cases of one group share a folder and a process (default: the case alone)
    check: Callable[[Path, str, str], object] | None = None  # more assertions: (folder, stdout, stderr)
    creates: tuple[str, ...] = ()  # files the command may create outside out/


def _set(path: str, value) -> Callable[[dict], None]:
    """A change that sets one field, ``a.b[2].c`` style."""

    def change(doc: dict) -> None:
        keys = [int(k) if k.isdigit() else k for k in path.replace("[", ".").replace("]", "").split(".")]
        node = doc
        for k in keys[:-1]:
            node = node[k] if isinstance(k, int) else node.setdefault(k, {})
        node[keys[-1]] = value

    return change


def _delete(path: str) -> Callable[[dict], None]:
    def change(doc: dict) -> None:
        *parents, last = path.split(".")
        node = doc
        for k in parents:
            node = node[k]
        del node[last]

    return change


def _fifo(rel: str) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        os.mkfifo(folder / rel)

    return setup


def _no_raw_markup(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    assert "<script>alert" not in text and "&lt;script&gt;" in text and "\x1b" not in text


def _link(rel: str, target: str) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        os.symlink(target, folder / rel)

    return setup


def _big_polygon(n: int) -> Callable[[dict], None]:
    def change(cell: dict) -> None:
        import math

        cell["table"]["polygons"] = [[[0.3 * math.cos(2 * math.pi * i / n), 0.3 * math.sin(2 * math.pi * i / n)]
                                      for i in range(n)]]

    return change


def _long_fence(n: int) -> Callable[[dict], None]:
    def change(cell: dict) -> None:
        cell["fences"].append({"points": [[-2.0 + 4.0 * i / n, -2.5] for i in range(n)], "top": 2.0})

    return change


def _many_devices(cell: dict) -> None:
    curtain = next(d for d in cell["devices"] if d["type"] == "light-curtain")
    cell["devices"] += [dict(curtain, name=f"c{i}") for i in range(5000)]


def _named_start(xy) -> Callable[[dict], None]:
    def change(cell: dict) -> None:
        cell["human"]["starts"] = [{"name": "far", "xy": xy, "heading_deg": 0.0, "phase": 0.0}]

    return change


def _write(rel: str, data: bytes) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_bytes(data)

    return setup


def _task(**task) -> Callable[[dict], None]:
    def change(cell: dict) -> None:
        cell["robot"]["task"] = task

    return change


def _stopping(**block) -> Callable[[dict], None]:
    """The robot's stopping block (issue 28) instead of its stopping_time."""
    def change(cell: dict) -> None:
        cell["robot"].pop("stopping_time", None)
        cell["robot"]["stopping"] = block

    return change


_STOP_HEAD = b"joint,category,speed_pct,payload_kg,extension_pct,distance,unit,time_s\n"
_CSV_HEAD = b"time,q1,q2,q3,q4,q5,q6\n0,1.4,-0.8,1.3,-2.1,-1.57,0\n"
_ENTITY_BOMB = (b'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
                + b"".join(f'<!ENTITY {chr(98 + i)} "{("&" + chr(97 + i) + ";") * 10}">'.encode() for i in range(8))
                + b']><robot name="r"><link name="&i;"/></robot>')

# ---- issue 29 (helper harden): helpers for the second round's inputs ------------------------------------------
SECRET = b"root:x:0:0:SECRET-TOKEN-29:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n"


def _device(kind: str, **change) -> Callable[[dict], None]:
    """A change of the first device of type ``kind``."""

    def apply(cell: dict) -> None:
        next(d for d in cell["devices"] if d["type"] == kind).update(change)

    return apply


def _warning_field(scale: float, dx: float = 0.0) -> Callable[[dict], None]:
    """A warning field made from the protective field, scaled about the origin and shifted along x."""

    def apply(cell: dict) -> None:
        scanner = next(d for d in cell["devices"] if d["type"] == "laser-scanner")
        scanner["warning"] = {"polygon": [[x * scale + dx, y * scale] for x, y in scanner["polygon"]]}

    return apply


def _in_home(name: str, data: bytes) -> Callable[[Path], None]:
    """A file in the HOME the child processes get (the corpus's root/home), for ``~/`` paths."""

    def setup(folder: Path) -> None:
        home = folder.parents[1] / "home"
        home.mkdir(parents=True, exist_ok=True)
        (home / name).write_bytes(data)

    return setup


def _quotes_nothing(*secrets: str) -> Callable[[Path, str, str], None]:
    def check(folder: Path, out: str, err: str) -> None:
        for w in secrets:
            assert w not in out + err, f"{w!r} quoted: {err[-500:]}"

    return check


def _manifest(**change) -> bytes:
    """A campaign.json of the right types (for the corpus's campaign command on baseline), then changed."""
    doc = {"format": 1, "cellstress_version": "0", "cells": [{"name": "baseline", "source": "baseline",
                                                             "sha256": "0" * 64}],
           "searchers": [{"name": "random", "params": {}}], "seeds": [0], "budget": 2, "until": "first", "runs": 1}
    doc.update(change)
    return json.dumps(doc).encode()


def _twice(key: str, value: object) -> Callable[[dict], None]:
    """A change that makes ``params`` hold ``key`` twice: an int key and a text key are both written as "key"."""

    def apply(doc: dict) -> None:
        doc["params"] = {int(key): value, key: value}

    return apply


def _risks(n: int) -> Callable[[dict], None]:
    return _set("risk_per_episode", [0.25] * n)


# ---- cell files that must be refused (exit 2), by every command that reads a cell ---------------------------
BAD_CELLS: list[tuple[str, dict, tuple[str, ...]]] = [
    ("fifo", {"setup": _fifo(CELL)}, ("cell.yaml", "not a regular file")),
    ("dev-zero", {"setup": _link(CELL, "/dev/zero")}, ("cell.yaml", "not a regular file")),
    ("directory", {"setup": lambda f: (f / CELL).mkdir()}, ("cell.yaml",)),
    ("too-big", {"cell_bytes": b"name: x\n" + b"#" * (11 * 2**20) + b"\n"}, ("cell.yaml", "too large")),
    ("alias-bomb", {"cell_bytes": b"a: &a [x,x,x,x,x,x,x,x,x,x]\n" + b"".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},"
        f"*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)}]\n".encode()
        for i in range(9))}, ("cell.yaml",)),
    ("deep-nesting", {"cell_bytes": b"name: " + b"[" * 50_000 + b"]" * 50_000 + b"\n"}, ("cell.yaml",)),
    ("deep-mapping", {"cell_bytes": b"".join(b"  " * i + b"a:\n" for i in range(3000))}, ("cell.yaml",)),
    ("binary", {"cell_bytes": bytes(range(256)) * 64}, ("cell.yaml",)),
    ("polygon-20000", {"cell": _big_polygon(20_000)}, ("table.polygons",)),
    ("fence-20000", {"cell": _long_fence(20_000)}, ("fences",)),
    ("devices-5000", {"cell": _many_devices}, ("devices",)),
    ("upper-arm-5m", {"cell": _set("human.anthropometry.upper_arm", 5.0)}, ("upper_arm",)),
    ("dwell-1e6", {"cell": _set("robot.task.dwell", 1e6)}, ("dwell",)),
    ("waypoint-1e6-deg", {"cell": _set("robot.task.waypoints_deg[0][0]", 1e6)}, ("waypoints_deg",)),
    ("speed-scale-tiny", {"cell": _set("robot.task.speed_scale", 1e-12)}, ("speed_scale",)),
    ("floor-huge", {"cell": _set("floor.xmax", 1e9)}, ("floor.xmax",)),
    ("phase-huge", {"cell": _set("robot.task.phase", 1e12)}, ("phase",)),
    ("bool-as-number", {"cell": _set("robot.stopping_time", True)}, ("stopping_time",)),
    ("text-as-number", {"cell": _set("robot.stopping_time", "0.15")}, ("stopping_time",)),
    ("nan", {"cell": _set("devices[0].response_time", float("nan"))}, ("response_time",)),
    ("infinity", {"cell": _set("table.height", float("inf"))}, ("table.height",)),
    ("negative-time", {"cell": _set("devices[1].response_time", -0.05)}, ("response_time",)),
    ("huge-integer", {"cell": _set("floor.ymax", 10**400)}, ("floor.ymax",)),
    ("start-far-away", {"cell": _set("human.start.xy", [100.0, 100.0])}, ("human.start",)),
    ("named-start-far-away", {"cell": _named_start([100.0, 100.0])}, ("human.starts",)),
    ("named-start-in-table", {"cell": _named_start([0.0, 0.0])}, ("human.starts",)),
    ("name-with-nul", {"cell": _set("name", "a\x00b")}, ("name",)),
    ("name-with-escape", {"cell": _set("name", "\x1b[2J\x1b[31mred")}, ("name",)),
    ("name-bidi-override", {"cell": _set("name", "abc\u202edcba")}, ("name",)),
    ("device-name-newline", {"cell": _set("devices[0].name", "a\nb")}, ("devices",)),
    ("name-too-long", {"cell": _set("name", "n" * 10_000)}, ("name",)),
    ("unknown-field", {"cell": _set("evil", 1)}, ("evil",)),
    ("unknown-device", {"cell": _set("devices[0].type", "laser-cannon")}, ("devices",)),
    ("urdf-etc-passwd", {"cell": _set("robot.urdf", "/etc/passwd")}, ("robot.urdf",)),
    ("urdf-fifo", {"cell": _set("robot.urdf", "pipe.urdf"), "setup": _fifo("in/pipe.urdf")}, ("robot.urdf",)),
    ("urdf-short-name-unknown", {"cell": _set("robot.urdf", "kuka")}, ("robot.urdf", "neither a built-in robot")),
    ("urdf-entity-bomb", {"cell": _set("robot.urdf", "bomb.urdf"), "setup": _write("in/bomb.urdf", _ENTITY_BOMB)},
     ("robot.urdf",)),
    ("waypoint-beyond-limit", {"cell": _set("robot.task.waypoints_deg[1][2]", 900.0)},
     ("waypoints_deg[1][2]", "elbow_joint", "limits")),
    ("csv-fifo", {"cell": _task(trajectory_csv="q.csv"), "setup": _fifo("in/q.csv")},
     ("trajectory_csv", "not a regular file")),
    ("csv-not-a-number", {"cell": _task(trajectory_csv="q.csv"),
                          "setup": _write("in/q.csv", _CSV_HEAD + b"1,1.4,-0.8,1e999,-2.1,-1.57,0\n")},
     ("trajectory_csv", "row 3, column 4")),
    ("csv-many-rows", {"cell": _task(trajectory_csv="q.csv"),
                       "setup": _write("in/q.csv", _CSV_HEAD + b"0,0,0,0,0,0,0\n" * 300_000)},
     ("trajectory_csv", "more than 200,000 rows")),
    ("csv-binary", {"cell": _task(trajectory_csv="q.csv"), "setup": _write("in/q.csv", bytes(range(256)) * 64)},
     ("trajectory_csv",)),
    ("ik-pose-far-away", {"cell": _task(tool_frame="tool0", poses=[{"xyz": [0.5, 0.5, 1.0], "rpy_deg": [180, 0, 0]},
                                                                   {"xyz": [50.0, 0, 1], "rpy_deg": [0, 0, 0]}])},
     ("robot.task.poses[1]", "cannot be reached")),
    ("obstacle-polygon-20000", {"cell": _set("obstacles", [{"name": "x", "height": 1.0, "polygon": [
        [3.0 + 0.5 * math.cos(2 * math.pi * i / 20_000), 0.5 * math.sin(2 * math.pi * i / 20_000)]
        for i in range(20_000)]}])}, ("obstacles",)),
    ("obstacles-5000", {"cell": _set("obstacles", [{"name": f"o{i}", "height": 1.0,
                                                    "box": {"center": [2.0, 0.0], "size": [0.1, 0.1]}}
                                                   for i in range(5000)])}, ("obstacles",)),
    ("obstacle-two-footprints", {"cell": _set("obstacles", [{"name": "x", "height": 1.0, "box": {
        "center": [2.0, 0.0], "size": [0.1, 0.1]}, "polygon": [[0, 0], [1, 0], [1, 1]]}])},
     ("obstacles", "exactly one of polygon and box")),
    ("obstacle-on-start", {"cell": _set("obstacles", [{"name": "crate", "height": 0.5, "box": {
        "center": [0.7, 3.35], "size": [0.4, 0.4]}}])}, ("human.start", "crate")),
    ("arrival-backwards", {"cell": _set("human.arrival", {"start": 5.0, "end": 1.0})}, ("human.arrival",)),
    ("arrival-unknown", {"cell": _set("human.arrival", "sometimes")}, ("human.arrival",)),
    ("stopping-and-stopping-time", {"cell": _set("robot.stopping", {"time": 0.2})},
     ("robot", "stopping_time or a stopping block")),
    ("stopping-category-9", {"cell": _stopping(category=9, time=0.2)}, ("robot.stopping.category",)),
    ("stopping-data-without-payload", {"cell": _stopping(data="s.csv")}, ("robot.stopping", "payload_kg")),
    ("stopping-data-fifo", {"cell": _stopping(data="s.csv", payload_kg=1.0), "setup": _fifo("in/s.csv")},
     ("robot.stopping.data", "s.csv", "not a regular file")),
    ("stopping-data-bad-category", {"cell": _stopping(data="s.csv", payload_kg=1.0), "setup": _write(
        "in/s.csv", _STOP_HEAD + b"shoulder_pan_joint,7,100,5,100,0.3,rad,0.2\n")},
     ("robot.stopping.data", "row 2, column 2 (category)")),
    ("stopping-data-many-rows", {"cell": _stopping(data="s.csv", payload_kg=1.0), "setup": _write(
        "in/s.csv", _STOP_HEAD + b"shoulder_pan_joint,1,100,5,100,0.3,rad,0.2\n" * 20_000)},
     ("robot.stopping.data", "more than 10,000 rows")),
    ("stopping-data-binary", {"cell": _stopping(data="s.csv", payload_kg=1.0),
                              "setup": _write("in/s.csv", bytes(range(256)) * 64)}, ("robot.stopping.data",)),
    ("stopping-data-below-program", {"cell": _stopping(data="s.csv", payload_kg=1.0), "setup": _write(
        "in/s.csv", _STOP_HEAD + b"shoulder_pan_joint,1,10,5,100,0.3,rad,0.2\n")},
     ("robot.stopping.data", "shoulder_pan_joint", "never extrapolated")),
    ("python-tag", {"cell_bytes": b"!!python/object/apply:os.system ['touch pwned']\n"}, ("cell.yaml",)),
    ("list-at-top", {"cell_bytes": b"- a\n- b\n"}, ("cell.yaml",)),
    # issue 29 (helper harden): rows counted whatever ends them, other files never quoted, clock windows, fields
    ("csv-200001-rows-no-final-newline", {"cell": _task(trajectory_csv="q.csv"), "setup": _write(
        "in/q.csv", _CSV_HEAD + b"0,0,0,0,0,0,0\n" * 199_999 + b"0,0,0,0,0,0,0")}, ("trajectory_csv", "200,000 rows")),
    ("csv-rows-end-in-cr", {"cell": _task(trajectory_csv="q.csv"), "setup": _write(
        "in/q.csv", (_CSV_HEAD + b"0,0,0,0,0,0,0\n" * 250_000).replace(b"\n", b"\r"))},
     ("trajectory_csv", "200,000 rows")),
    ("csv-etc-passwd", {"cell": _task(trajectory_csv="/etc/passwd"), "check": _quotes_nothing("root:x", "bash")},
     ("trajectory_csv", "/etc/passwd", "row 1", "header must be")),
    ("csv-secret-in-home", {"cell": _task(trajectory_csv="~/secret.csv"), "setup": _in_home("secret.csv", SECRET),
                            "check": _quotes_nothing("SECRET", "root:x")}, ("trajectory_csv", "secret.csv", "row 1")),
    ("csv-secret-in-header", {"cell": _task(trajectory_csv="q.csv"), "setup": _write(
        "in/q.csv", b"time,q1,q2,q3,q4,q5,SECRET-TOKEN-29\n0,1.4,-0.8,1.3,-2.1,-1.57,0\n"),
        "check": _quotes_nothing("SECRET")}, ("trajectory_csv", "column 7 should be q6")),
    ("csv-secret-in-a-value", {"cell": _task(trajectory_csv="q.csv"), "setup": _write(
        "in/q.csv", _CSV_HEAD + b"1,1.4,-0.8,SECRET-TOKEN-29,-2.1,-1.57,0\n"), "check": _quotes_nothing("SECRET")},
     ("trajectory_csv", "row 3, column 4", "not a number")),
    ("csv-huge-value", {"cell": _task(trajectory_csv="q.csv"), "setup": _write(
        "in/q.csv", _CSV_HEAD + b"1,1.4,-0.8,123456789012345678,-2.1,-1.57,0\n"),
        "check": _quotes_nothing("123456789012345678")}, ("trajectory_csv", "row 3, column 4", "sensible size")),
    ("muting-500-s", {"cell": _device("light-curtain", muting={"pallet": [0.0, 2.0], "until": 500.0})},
     ("muting", "lasts 500 s", "longer than the robot's cycle")),
    ("muting-wraps-past-a-cycle", {"cell": _device("light-curtain", muting={"pallet": [5.0, 5.5], "until": 12.0})},
     ("muting", "lasts 7 s", "longer than the robot's cycle")),
    ("muting-after-the-cycle", {"cell": _device("light-curtain", muting={"pallet": [30.0, 31.0], "until": 31.0})},
     ("muting", "starts at 30 s", "after the robot's cycle")),
    ("warning-field-inside", {"cell": _warning_field(0.5)}, ("devices", "warning.polygon must contain")),
    ("warning-field-apart", {"cell": _warning_field(1.0, dx=20.0)}, ("devices", "warning.polygon must contain")),
    ("warning-field-overlapping", {"cell": _warning_field(1.0, dx=0.3)}, ("devices", "warning.polygon must contain")),
    ("scanner-resolution-nan", {"cell": _device("laser-scanner", resolution_mm=float("nan"))},
     ("devices", "resolution_mm")),
    ("scanner-resolution-negative", {"cell": _device("laser-scanner", resolution_mm=-70.0)},
     ("devices", "resolution_mm")),
    ("scanner-resolution-huge", {"cell": _device("laser-scanner", resolution_mm=1e300)}, ("devices", "resolution_mm")),
]


# ---- robot files (issue 29; helper robotgeo): URDFs and meshes from hostile users ---------------------------
# The baseline with its robot replaced by the built-in primitive arm as in/robot.urdf, changed per case (and
# mesh files beside it). Every command that reads a cell refuses each with one error line that names the file
# and the cause in our words (pinocchio's own lines on file descriptor 2 are captured), before any parser that
# could crash or take unbounded time sees it.
_ARM = resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf").read_text(encoding="utf-8")
_FOREARM = ('<collision><origin xyz="0 0 0.286" rpy="0 0 0"/><geometry><cylinder radius="0.05" length="0.572"/>'
            "</geometry></collision>")
_TRIS = [((0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.0, 0.1, 0.0)), ((0.0, 0.0, 0.0), (0.0, 0.1, 0.0), (0.0, 0.0, 0.1))]


def _stl(triangles, count: int | None = None) -> bytes:
    import struct

    rows = b"".join(struct.pack("<12fH", 0, 0, 0, *[c for v in t for c in v], 0) for t in triangles)
    return b"\0" * 80 + struct.pack("<I", len(triangles) if count is None else count) + rows


def _sparse_stl(rel: str, n: int) -> Callable[[Path], None]:
    """A binary STL whose header and size agree on n triangles, written sparse (100 MB cost nothing)."""
    def setup(folder: Path) -> None:
        with (folder / rel).open("wb") as fh:
            fh.write(b"\0" * 80 + n.to_bytes(4, "little"))
            fh.truncate(84 + 50 * n)

    return setup


def _robot(urdf: str | bytes, *more: Callable[[Path], None], cell: Callable[[dict], None] | None = None) -> dict:
    data = urdf.encode("utf-8") if isinstance(urdf, str) else urdf

    def setup(folder: Path) -> None:
        _write("in/robot.urdf", data)(folder)
        for m in more:
            m(folder)

    def change(doc: dict) -> None:
        _set("robot.urdf", "robot.urdf")(doc)
        if cell is not None:
            cell(doc)

    return {"cell": change, "setup": setup}


def _arm_mesh(filename: str) -> str:
    return _ARM.replace(_FOREARM, f'<collision><geometry><mesh filename="{filename}"/></geometry></collision>')


def _chain(n: int) -> str:
    joints = "".join(f'<link name="l{i + 1}"/><joint name="j{i}" type="revolute"><parent link="l{i}"/><child '
                     f'link="l{i + 1}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/>'
                     "</joint>" for i in range(n))
    return f'<?xml version="1.0"?><robot name="r"><link name="l0"/>{joints}</robot>'


def _baxter_poses(doc: dict) -> None:
    from cellstress.robot.model import example_robot_data_share

    doc["robot"]["urdf"] = str(example_robot_data_share() / "robots/baxter_description/urdf/baxter.urdf")
    doc["robot"]["extra_capsules"] = []
    doc["robot"]["task"] = {"tool_frame": "left_gripper", "poses": [
        {"xyz": [0.6, 0.3, 1.0], "rpy_deg": [180, 0, 0]}, {"xyz": [0.6, -0.3, 1.0], "rpy_deg": [180, 0, 0]}]}


BAD_ROBOT_FILES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("mesh-missing", _robot(_arm_mesh("nothere.stl")), ("robot.urdf", "forearm_link", "nothere.stl", "no such file")),
    ("mesh-etc-passwd", _robot(_arm_mesh("/etc/passwd")), ("robot.urdf", "/etc/passwd", "without an extension")),
    ("mesh-passwd-as-stl", _robot(_arm_mesh("passwd.stl"), _link("in/passwd.stl", "/etc/passwd")),
     ("passwd.stl", "is not an STL file")),
    ("mesh-dev-zero", _robot(_arm_mesh("zero.stl"), _link("in/zero.stl", "/dev/zero")),
     ("zero.stl", "not a regular file")),
    ("mesh-dev-zero-path", _robot(_arm_mesh("/dev/zero")), ("/dev/zero", "without an extension")),
    ("mesh-fifo", _robot(_arm_mesh("pipe.stl"), _fifo("in/pipe.stl")), ("pipe.stl", "not a regular file")),
    ("mesh-directory", _robot(_arm_mesh("dir.stl"), lambda f: (f / "in" / "dir.stl").mkdir()),
     ("dir.stl", "directory")),
    ("mesh-0-triangles", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl([]))), ("m.stl", "no triangles")),
    ("mesh-degenerate", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl([((0, 0, 0), (0.1, 0, 0), (0.2, 0, 0))]))),
     ("m.stl", "zero area")),
    ("mesh-header-10M", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl(_TRIS, count=10_000_000))),
     ("m.stl", "header says 10,000,000 triangles")),
    ("mesh-nan", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl([((0, 0, 0), (math.nan, 0, 0), (0, 1, 0))]))),
     ("m.stl", "not finite")),
    ("mesh-inf", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl([((0, 0, 0), (0, math.inf, 0), (0, 1, 0))]))),
     ("m.stl", "not finite")),
    ("mesh-1e30", _robot(_arm_mesh("m.stl"), _write("in/m.stl", _stl([((0, 0, 0), (1e30, 0, 0), (0, 1, 0))]))),
     ("m.stl", "1e+30 m from its origin")),
    ("mesh-100MB", _robot(_arm_mesh("m.stl"), _sparse_stl("in/m.stl", 2_000_000)), ("m.stl", "too large")),
    ("mesh-500k-triangles", _robot(_arm_mesh("m.stl"), _sparse_stl("in/m.stl", 500_000)),
     ("m.stl", "500,000 triangles", "at most 400,000")),
    ("mesh-dae-junk", _robot(_arm_mesh("m.dae"), _write("in/m.dae", b"<COLLADA>junk")),
     ("m.dae", "cannot be read as a mesh")),
    ("mesh-dae-entities", _robot(_arm_mesh("m.dae"), _write("in/m.dae", b'<?xml version="1.0"?><!DOCTYPE c '
                                                                      b'[<!ENTITY a "aaaa">]><COLLADA>&a;</COLLADA>')),
     ("m.dae", "entities")),
    ("mesh-format-unknown", _robot(_arm_mesh("m.blend"), _write("in/m.blend", b"BLENDER")), ("m.blend", "'.blend'")),
    ("urdf-nan-limit", _robot(_ARM.replace('upper="3.14159265359"', 'upper="nan"')),
     ("robot.urdf", "elbow_joint", "<limit upper>", "not finite")),
    ("urdf-inf-limit", _robot(_ARM.replace('velocity="3.15"', 'velocity="-inf"')), ("<limit velocity>", "not finite")),
    ("urdf-cycle", _robot(_ARM.replace("</robot>", '<joint name="loop" type="fixed"><parent link="gripper"/>'
                                                   '<child link="base_link"/></joint></robot>')), ("cycle",)),
    ("urdf-two-parents", _robot(_ARM.replace("</robot>", '<joint name="loop" type="fixed"><parent link="gripper"/>'
                                                         '<child link="shoulder_link"/></joint></robot>')),
     ("shoulder_link", "child of two joints")),
    ("urdf-disconnected", _robot(_ARM.replace("</robot>", '<link name="loose"/></robot>')),
     ("not connected", "loose")),
    ("urdf-duplicate-link", _robot(_ARM.replace('<link name="tool0"/>', '<link name="tool0"/><link name="tool0"/>')),
     ("tool0", "defined twice")),
    ("urdf-empty", _robot(""), ("robot.urdf", "is empty")),
    ("urdf-utf16", _robot(_ARM.encode("utf-16")), ("robot.urdf", "UTF-16")),
    ("urdf-10000-joints", _robot(_chain(10_000)), ("robot.urdf", "10,000 joints", "at most 500")),
    ("urdf-axis-zero", _robot(_ARM.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1)),
     ("shoulder_pan_joint", "<axis xyz>", "is zero")),
    ("urdf-origin-1e30", _robot(_ARM.replace('xyz="0.0 0.1149 0.0"', 'xyz="1e30 0 0"')),
     ("wrist_2_joint", "<origin xyz>", "100 m")),
    ("urdf-moving-mass-without-shape", _robot(_ARM.replace(_FOREARM, "")),
     ("forearm_link", "3.9 kg", "no <collision> or <visual> shape")),
    ("urdf-no-shape-at-all", _robot(_chain(6), cell=_set("robot.task.waypoints_deg", [[0] * 6, [10] * 6])),
     ("no link has a <collision> or <visual> shape",)),
    ("tree-robot-tool-poses", {"cell": _baxter_poses}, ("robot.task.poses", "branches", "robot.hold")),
]
BAD_CELLS += BAD_ROBOT_FILES


def _cell_cases() -> list[Case]:
    out = []
    for name, spec, says in BAD_CELLS:
        for command, argv in CELL_COMMANDS.items():
            out.append(Case(f"cell-{name}-{command}", argv, 2, says, group=f"cell-{name}", **spec))
    return out


# ---- result files: malformed ones are refused (2), forged ones do not replay (1) ----------------------------
BAD_RESULTS: list[tuple[str, dict, tuple[str, ...]]] = [
    ("not-json", {"result_bytes": b"{"}, ("result.json", "invalid JSON")),
    ("deep-json", {"result_bytes": b"[" * 100_000 + b"]" * 100_000}, ("result.json",)),
    ("top-level-list", {"result_bytes": b"[]"}, ("result.json",)),
    ("hazard-is-text", {"result": _set("hazard", "boom")}, ("hazard",)),
    ("cell-is-list", {"result": _set("cell", [1, 2])}, ("cell",)),
    ("trace-missing", {"result": _delete("hazard.trace")}, ("hazard.trace",)),
    ("v_R-text", {"result": _set("hazard.v_R", "fast")}, ("hazard.v_R",)),
    ("seed-negative", {"result": _set("seed", -1)}, ("seed",)),
    ("seed-bool", {"result": _set("seed", True)}, ("seed",)),
    ("budget-huge", {"result": _set("budget", 10**12)}, ("budget",)),
    ("format-2", {"result": _set("format", 2)}, ("format",)),
    ("unknown-field", {"result": _set("evil", 1)}, ("evil",)),
    ("actions-100k", {"result": _set("hazard.actions", ["walk+upright"] * 100_000)}, ("hazard.actions",)),
    ("searcher-long", {"result": _set("searcher", "s" * 100_000)}, ("searcher",)),
    ("sha-not-hex", {"result": _set("cell.sha256", "z" * 64)}, ("cell.sha256",)),
    ("result-fifo", {"setup": _fifo(RESULT)}, ("result.json", "not a regular file")),
    ("result-dev-zero", {"setup": _link(RESULT, "/dev/zero")}, ("result.json", "not a regular file")),
    ("result-too-big", {"result_bytes": b" " * (11 * 2**20) + b"{}"}, ("result.json", "too large")),
    ("cell-source-fifo", {"result": _set("cell.source", "{folder}/in/pipe.yaml"), "setup": _fifo("in/pipe.yaml")},
     ("pipe.yaml", "not a regular file")),
    ("cell-source-dev-zero", {"result": _set("cell.source", "/dev/zero")}, ("/dev/zero",)),
    ("cell-source-missing", {"result": _set("cell.source", "{folder}/in/nothing.yaml")}, ("nothing.yaml",)),
    ("cell-source-etc-passwd", {"result": _set("cell.source", "/etc/passwd")}, ("/etc/passwd",)),
    ("action-unknown", {"result": _set("hazard.actions", ["walk+upright", "fly+upright"])}, ("fly+upright",)),
    ("phase-not-a-number", {"result": _set("hazard.actions", ["phase:nan", "walk+upright"])}, ("phase:nan",)),
    ("why-text", {"result": _set("hazard.why", "because")}, ("hazard.why",)),
    ("severity-text", {"result": _set("hazard.severity.v_R", "fast")}, ("hazard.severity.v_R",)),
    ("severity-negative", {"result": _set("hazard.severity.v_R", -1.0)}, ("hazard.severity.v_R",)),
    ("severity-creeping-text", {"result": _set("hazard.severity.creeping", "no")}, ("hazard.severity.creeping",)),
    # issue 29 (helper harden): lists that disagree with the episodes, keys given twice, the files a cell read
    ("risks-600000", {"result": _risks(600_000)}, ("risk_per_episode", "600,000 values")),
    ("risks-one-short", {"result": lambda d: d.update(risk_per_episode=d["risk_per_episode"][:-1])},
     ("risk_per_episode",)),
    ("episodes-over-budget", {"result": lambda d: d.update(episodes=d["budget"] + 1)}, ("episodes", "budget")),
    ("hazard-list-beyond", {"result": _set("hazards[0].episode", 10**6)}, ("hazards[0].episode",)),
    ("top-list-too-long", {"result": lambda d: d.update(top=d["top"] * 1000)}, ("top",)),
    ("distinct-sequences-over", {"result": _set("distinct_sequences", 10**6)}, ("distinct_sequences",)),
    ("key-twice-in-params", {"result": _twice("7", 0.5)}, ("result.json", "'7' appears twice")),
    ("files-20000", {"result": lambda d: d["cell"].update(files=d["cell"]["files"] * 2000)}, ("cell.files",)),
    ("files-path-escape", {"result": _set("cell.files[1].path", "a\x1b[2Jb")}, ("cell.files[1].path",)),
    ("files-sha-not-hex", {"result": _set("cell.files[1].sha256", "z" * 64)}, ("cell.files[1].sha256",)),
    ("files-bytes-text", {"result": _set("cell.files[1].bytes", "many")}, ("cell.files[1].bytes",)),
    ("files-entry-text", {"result": _set("cell.files", ["/etc/passwd"])}, ("cell.files[0]",)),
]

FORGED: list[tuple[str, Callable[[dict], None], str]] = [
    ("time", _set("hazard.time_s", 0.123), "hazard.time_s"),
    ("step", _set("hazard.step", 2), "hazard.step"),
    ("link", _set("hazard.robot_link", "base_link"), "hazard.robot_link"),
    ("part", _set("hazard.body_part", "head"), "hazard.body_part"),
    ("trace-row", _set("hazard.trace[1].x", 9.0), "hazard.trace[1].x"),
    ("episode", _set("hazard.episode", 39), "hazard.episode"),
    ("seed", _set("seed", 11), "seed 11"),
    ("found", _set("found", False), "found"),
    ("risks", _set("risk_per_episode[0]", 1e-3), "risk_per_episode[0]"),
    ("cell-hash", _set("cell.sha256", "0" * 64), "cell.sha256"),
    ("why-late", _set("hazard.why.contact_at_s", 0.05), "hazard.why.contact_at_s"),
    ("severity-milder", _set("hazard.severity.v_R", 0.001), "hazard.severity.v_R"),
    ("severity-creeping", _set("hazard.severity.creeping", True), "hazard.severity.creeping"),
    ("searcher-unknown", _set("searcher", "<script>alert(1)</script>"), "searcher"),
    # issue 29 (helper harden): replay names the file that differs
    ("file-hash", _set("cell.files[1].sha256", "0" * 64), "cell.files"),
    ("file-missing", lambda d: d["cell"].update(files=d["cell"]["files"][:-1]), "cell.files"),
    ("file-extra", lambda d: d["cell"]["files"].append(dict(d["cell"]["files"][1], path="/elsewhere/x.stl")),
     "cell.files"),
]


def _result_cases() -> list[Case]:
    out = []
    for name, spec, says in BAD_RESULTS:
        for command in ("replay", "report"):
            out.append(Case(f"result-{name}-{command}", (command, RESULT), 2, says, group=f"result-{name}",
                            **spec))
    for name, change, says in FORGED:
        out.append(Case(f"forged-{name}-replay", ("replay", RESULT), 1, (says,), result=change))
    return out


# ---- strange but valid names: the commands work, and the text is escaped where it lands ---------------------
SCRIPT = "<script>alert(1)</script>"
FORMULA = '=HYPERLINK("http://example.invalid","x")'


def _no_raw(*words: str, files: tuple[str, ...] = ()) -> Callable[[Path, str, str], None]:
    def check(folder: Path, out: str, err: str) -> None:
        assert "\x1b" not in out + err
        for rel in files:
            text = (folder / rel).read_text(encoding="utf-8")
            for w in words:
                assert w not in text, f"{w!r} unescaped in {rel}"

    return check


def _csv_neutral(folder: Path, out: str, err: str) -> None:
    lines = (folder / "out" / "table.csv").read_text(encoding="utf-8").splitlines()[1:]
    assert lines and all(not line.startswith(("=", "+", "-", "@", '"=')) for line in lines), lines


def _md_cell_escaped(folder: Path, out: str, err: str) -> None:
    text = (folder / "out" / "table.md").read_text(encoding="utf-8")
    assert "a\\|b" in text and "<b>" not in text


def _slug_only(folder: Path, out: str, err: str) -> None:
    pngs = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*.png"))
    assert pngs == ["x.png"], pngs


CAMPAIGN = CELL_COMMANDS["campaign"]
NAMED: list[Case] = [
    Case("name-script-search-report", ("search", CELL, "--budget", "2", "--searcher", "random", "--out", "out"), 0,
         cell=_set("name", SCRIPT), check=_no_raw(SCRIPT, files=("out/report.html",))),
    Case("name-script-campaign", CAMPAIGN, 0, cell=_set("name", SCRIPT),
         check=_no_raw(SCRIPT, files=("out/report.html", "out/table.md"))),
    Case("device-name-script-report", ("search", CELL, "--budget", "2", "--searcher", "random", "--out", "out"), 0,
         cell=_set("devices[0].name", SCRIPT), check=_no_raw(SCRIPT, files=("out/report.html",))),
    Case("name-formula-campaign", CAMPAIGN, 0, cell=_set("name", FORMULA), check=_csv_neutral),
    Case("name-pipe-campaign", CAMPAIGN, 0, cell=_set("name", "a|b<b>"), check=_md_cell_escaped),
    Case("name-dollar-show", ("show", CELL, "--out", "out/cell.png"), 0, cell=_set("name", "cost $5 $")),
    Case("device-name-dollar-show", ("show", CELL, "--out", "out/cell.png"), 0,
         cell=_set("devices[0].name", "$\\frac{1}{0}$")),
    Case("name-traversal-show", ("show", CELL), 0, cell=_set("name", "../../x"), creates=("x.png",),
         check=_slug_only),
    Case("name-absolute-show", ("show", CELL), 0, cell=_set("name", "/tmp/x"), creates=("tmp-x.png",)),
    Case("device-name-script-show-3d", ("show", CELL, "--3d", "--out", "out/cell.html"), 0,
         cell=_set("devices[0].name", SCRIPT), check=_no_raw(SCRIPT, "</script><script>", files=("out/cell.html",))),
    Case("description-escape-check", ("check", CELL), 0, cell=_set("description", "safe\x1b]0;owned\x07 cell"),
         check=_no_raw()),
    Case("campaign-runs-symlink-planted", ("campaign", "--cells", "baseline", "--searchers", "random", "--seeds",
                                           "1", "--budget", "2", "--workers", "1", "--out", "out"), 2,
         ("out",), setup=_link("out/runs.jsonl", "../in/victim.txt")),
    Case("report-symlink-planted", ("report", RESULT), 0, result=lambda d: None,
         setup=_link("out/report.html", "../in/victim.txt"),
         check=lambda folder, out, err: (
             (folder / "in" / "victim.txt").read_text() == "keep me\n" or pytest.fail("victim overwritten"),
             (folder / "out" / "report.html").is_symlink() and pytest.fail("report.html still a link"))),
]

# ---- options ------------------------------------------------------------------------------------------------
OPTIONS: list[Case] = [
    Case("search-budget-huge", ("search", "baseline", "--budget", str(10**12), "--out", "out"), 2, ("budget",)),
    Case("search-seed-negative", ("search", "baseline", "--seed", "-1", "--out", "out"), 2, ("seed",)),
    Case("search-top-k-huge", ("search", "baseline", "--top-k", str(10**9), "--out", "out"), 2, ("top_k",)),
    Case("search-candidates-huge", ("search", "s3-fence-gap", "-s", "plan", "--set", "candidates=1000000000",
                                    "--out", "out"), 2, ("candidates",)),
    Case("search-pool-inf", ("search", "baseline", "-s", "evolve", "--set", "pool=1e999", "--out", "out"), 2,
         ("pool",)),
    Case("search-ec-nan", ("search", "baseline", "--set", "ec=NaN", "--out", "out"), 2, ("ec",)),
    Case("search-unknown-searcher", ("search", "baseline", "-s", "../../evil", "--out", "out"), 2,
         ("unknown searcher",)),
    Case("search-unknown-criterion", ("search", "baseline", "--criterion", "<x>", "--out", "out"), 2,
         ("criterion",)),
    Case("search-out-is-a-file", ("search", "baseline", "--out", "in/file"), 2, ("--out",),
         setup=lambda f: (f / "in" / "file").write_text("x"), group="search-out-is-a-file"),
    Case("search-distinct-without-budget", ("search", "baseline", "--distinct", "--out", "out"), 2,
         ("--distinct",)),
    Case("campaign-seeds-huge", ("campaign", "--seeds", str(10**9), "--out", "out"), 2, ("--seeds",)),
    Case("campaign-workers-huge", ("campaign", "--workers", str(10**6), "--out", "out"), 2, ("--workers",)),
    Case("campaign-unknown-searcher", ("campaign", "--searchers", "nope", "--out", "out"), 2, ("nope",)),
    Case("campaign-unknown-cell", ("campaign", "--cells", "no-such-cell", "--out", "out"), 2, ("no-such-cell",)),
    Case("simulate-unknown-action", ("simulate", "baseline", "--actions", "walk+fly"), 2, ("walk+fly",)),
    Case("simulate-100k-actions", ("simulate", "baseline", "--actions", ",".join(["walk+upright"] * 5_000)), 2,
         ("actions",)),
    Case("replay-hazard-index", ("replay", RESULT, "--hazard", "5"), 2, ("--hazard 5",), result=lambda d: None,
         group="replay-hazard-index"),
    Case("show-not-png", ("show", "baseline", "--out", "out/x.txt"), 2, (".png",)),
    Case("show-3d-not-html", ("show", "baseline", "--3d", "--out", "out/x.png"), 2, (".html",)),
    Case("check-unknown-cell", ("check", "../../etc/passwd"), 2, ("passwd",)),
    # issue 29 (helper harden): workers bounded, nothing written through a link in --out, campaign.json checked
    Case("verify-workers-huge", ("verify", "baseline", "--workers", str(10**6), "--out", "out"), 2, ("--workers",)),
    Case("verify-workers-zero", ("verify", "baseline", "--workers", "0", "--out", "out"), 2, ("--workers",)),
    Case("search-set-key-twice", ("search", "baseline", "-s", "evolve", "--set", 'pool={"a": 1, "a": 2}', "--out",
                                  "out"), 2, ("--set pool", "'a' appears twice")),
    *(Case(f"verify-witness-{kind}-planted", ("verify", "s1-scanner-width", "--phases", "cell", "--horizon", "4",
                                             "--workers", "1", "--out", "out"), 2, ("witness-01", says),
           setup=setup, group=f"verify-witness-{kind}")
      for kind, setup, says in (("link", _link("out/witness-01", "../in"), "is a symbolic link"),
                                ("file", _write("out/witness-01", b"mine\n"), "is not a folder"),
                                ("dangling-link", _link("out/witness-01", "../nowhere"), "is a symbolic link"))),
    # issue 33: fix reads a cell like every command and writes only into --out
    Case("fix-budget-zero", ("fix", "baseline", "--budget", "0", "--out", "out"), 2, ("budget",)),
    Case("fix-time-limit-nan", ("fix", "baseline", "--time-limit", "nan", "--out", "out"), 2, ("--time-limit",)),
    Case("fix-out-is-a-file", ("fix", "baseline", "--out", "in/victim.txt"), 2, ("--out", "not a directory")),
    Case("fix-markup-name", ("fix", CELL, "--budget", "2", "--time-limit", "5", "--out", "out"), 0,
         cell=_set("name", "<script>alert(1)</script>"), group="fix-markup-name",
         check=lambda folder, out, err: _no_raw_markup(folder / "out" / "fix.html")),
    # issue 31: verify's checkpoint in --out is an input like any other; its options refuse markup and nonsense
    *(Case(f"verify-checkpoint-{kind}", ("verify", "baseline", "--phases", "cell", "--horizon", "1", "--workers", "1",
                                        "--out", "out"), 2, ("verify-checkpoint.jsonl", says),
           setup=setup, group=f"verify-checkpoint-{kind}")
      for kind, setup, says in (("link", _link("out/verify-checkpoint.jsonl", "../in/victim.txt"), "symbolic link"),
                                ("fifo", _fifo("out/verify-checkpoint.jsonl"), "not a regular file"),
                                ("garbage", _write("out/verify-checkpoint.jsonl", b"\x00\xff{[\n"), "line 1"),
                                ("foreign", _write("out/verify-checkpoint.jsonl", b'{"kind": "cellstress verify '
                                                   b'checkpoint", "cell_sha256": "0", "criterion": "x", "options": {}, '
                                                   b'"tasks": 1, "version": "0"}\n'), "another verification"))),
    Case("verify-phases-nan", ("verify", "baseline", "--phases", "nan:1", "--out", "out"), 2, ("phases", "finite")),
    Case("verify-phases-huge", ("verify", "baseline", "--phases", "1e300:1e301", "--out", "out"), 2,
         ("phases", "no arrival phase")),
    Case("verify-starts-markup", ("verify", "baseline", "--starts", "<script>\x1b[31m", "--out", "out"), 2,
         ("starts",)),
    *(Case(f"campaign-manifest-{name}", ("campaign", "--cells", "baseline", "--searchers", "random", "--seeds", "1",
                                        "--budget", "2", "--workers", "1", "--out", "out"), 2, ("campaign.json", *says),
           setup=setup, group=f"campaign-manifest-{name}")
      for name, setup, says in (
          ("cells-are-text", _write("out/campaign.json", _manifest(cells=["baseline"])), ("cells[0]",)),  # the crash
          ("searchers-text", _write("out/campaign.json", _manifest(searchers="random")), ("searchers",)),
          ("seeds-huge", _write("out/campaign.json", _manifest(seeds=list(range(200_000)))), ("seeds",)),
          ("budget-bool", _write("out/campaign.json", _manifest(budget=True)), ("budget",)),
          ("sha-not-hex", _write("out/campaign.json", _manifest(cells=[{"name": "baseline", "source": "baseline",
                                                                       "sha256": "x"}])), ("cells[0].sha256",)),
          ("key-twice", _write("out/campaign.json", _manifest()[:-1] + b', "budget": 3}'), ("'budget' appears twice",)),
          ("not-json", _write("out/campaign.json", b"{"), ("invalid JSON",)),
          ("list", _write("out/campaign.json", b"[]"), ("not a campaign manifest",)),
          ("fifo", _fifo("out/campaign.json"), ("not a regular file",)),
          ("link", _link("out/campaign.json", "../in/victim.txt"), ("symbolic link",)),
      )),
]

CASES = _cell_cases() + _result_cases() + NAMED + OPTIONS
# robot files that are strange but valid (robotgeo): a robot of URDF primitives only (boxes, cylinders and a
# capsule urdfdom does not know) is read and audited by check, with no stray line from the URDF parser; its box
# gripper, larger than the UR10's, dips into the table on the baseline's program, which the program check says
# (exit 1: a valid cell whose check fails)
_PRIMITIVE_ARM = _robot(_ARM.replace(_FOREARM, '<collision><origin xyz="0 0 0.286"/><geometry><capsule radius="0.05" '
                                                'length="0.47"/></geometry></collision>'))
CASES += [Case("robot-primitives-only-check", ("check", CELL), 1, group="robot-primitives-only", **_PRIMITIVE_ARM,
               check=lambda folder, out, err: (err == "" or pytest.fail(err), "outside by 0.000 mm" in out
                                               and "link gripper passes" in out and "static check fails (program)"
                                               in out or pytest.fail(out[-2000:]))),
          Case("robot-primitives-only-show", ("show", CELL, "--out", "out/cell.png"), 0, group="robot-primitives-only",
               **_PRIMITIVE_ARM, check=lambda folder, out, err: (folder / "out" / "cell.png").is_file()
               or pytest.fail("no picture"))]


def _snapshot(folder: Path) -> dict[str, bytes | str]:
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_symlink():
            out[rel] = "link:" + os.readlink(p)
        elif p.is_file():
            out[rel] = p.read_bytes() if p.stat().st_size < 2**20 else f"size:{p.stat().st_size}"
    return out


def _prepare(case: Case, folder: Path, baseline: dict, result: dict) -> None:
    (folder / "in").mkdir(parents=True, exist_ok=True)
    (folder / "in" / "victim.txt").write_text("keep me\n")
    if case.setup is not None:
        case.setup(folder)
    if case.cell is not None or case.cell_bytes is not None:
        data = case.cell_bytes
        if data is None:
            cell = copy.deepcopy(baseline)
            case.cell(cell)
            data = yaml.safe_dump(cell, sort_keys=False, allow_unicode=True, width=10**9).encode("utf-8")
        (folder / CELL).write_bytes(data)
    if case.result is not None or case.result_bytes is not None:
        data = case.result_bytes
        if data is None:
            doc = copy.deepcopy(result)
            case.result(doc)
            data = json.dumps(doc).replace("{folder}", str(folder)).encode("utf-8")
        (folder / "out").mkdir(exist_ok=True)
        (folder / RESULT).write_bytes(data)


@dataclass
class Ran:
    code: int | None
    out: str
    err: str
    before: dict = field(default_factory=dict)
    after: dict = field(default_factory=dict)


def _group(case: Case) -> str:
    if case.group:
        return case.group
    return "options" if case in OPTIONS else case.id


class _Forks:
    """A process that has imported cellstress and forks a child per group (``FORKS``), one group at a time."""

    def __init__(self, env: dict[str, str], log: Path) -> None:
        self.log = log
        with log.open("wb") as err:
            self.p = subprocess.Popen([sys.executable, "-c", FORKS], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=err, env=env, text=True)

    def run(self, folder: Path, commands: Path, report: Path) -> int | None:
        """The child's exit status; None when it ran out of time (and was killed)."""
        self.p.stdin.write(json.dumps({"cwd": str(folder), "commands": str(commands), "report": str(report)}) + "\n")
        self.p.stdin.flush()
        answer = self.p.stdout.readline()
        if not answer:
            raise RuntimeError(f"the fork server died: {self.log.read_text(errors='replace')[-1500:]}")
        return json.loads(answer)

    def close(self) -> None:
        self.p.stdin.close()
        self.p.wait(timeout=60)


def _run_group(cases: list[Case], folder: Path, commands: Path, forks: _Forks) -> list[Ran]:
    before = _snapshot(folder)
    commands.write_text(json.dumps([list(c.argv) for c in cases]))
    report = commands.with_suffix(".out.json")
    status = forks.run(folder, commands, report)
    if status is None:
        ran = [Ran(None, "", f"timed out after {TIME_LIMIT} s") for _ in cases]
    else:
        done = json.loads(report.read_text()) if status == 0 and report.exists() else []
        ran = [Ran(d["code"], d["out"], d["err"]) for d in done]
        if len(ran) != len(cases):
            ran = [Ran(-1, "", f"the process ended with {status} (its stderr: {forks.log})") for _ in cases]
    after = _snapshot(folder)
    for r in ran:
        r.before, r.after = before, after
    return ran


@pytest.fixture(scope="module")
def ran(tmp_path_factory, worker_id) -> dict[str, tuple[Path, Ran]]:
    """Every case's outcome, played once per test session: the first xdist worker to need it plays the corpus
    (minutes, two processes at a time) while the others wait on a lock, then read what it stored. (xdist's
    ``loadgroup`` would do it, but does not group under pytest 9.2.)"""
    shared = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        shared = shared.parent  # the session's folder, above each worker's own
    stored = shared / "hostile-ran.pickle"
    with open(shared / "hostile-ran.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not stored.exists():
            outcome = _play_corpus(tmp_path_factory)
            part = stored.with_suffix(".part")
            part.write_bytes(pickle.dumps(outcome))
            part.replace(stored)
    return pickle.loads(stored.read_bytes())


def _play_corpus(tmp_path_factory) -> dict[str, tuple[Path, Ran]]:
    root = tmp_path_factory.mktemp("hostile")
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    baseline = yaml.safe_load(text)
    made = root / "reference"
    assert main(["search", "s3-fence-gap", "--searcher", "plan", "--budget", "40", "--out", str(made),
                 "--no-report"]) == 0
    result = json.loads((made / "result.json").read_text())
    env = {k: v for k, v in os.environ.items() if not k.startswith(("COLUMNS", "FORCE_COLOR"))}
    env.update(HOME=str(root / "home"), CELLSTRESS_CACHE=os.environ.get("CELLSTRESS_CACHE",
                                                                      str(Path.home() / ".cache")))
    groups: dict[str, list[Case]] = {}
    for case in CASES:
        groups.setdefault(_group(case), []).append(case)
    (root / "commands").mkdir()
    folders = {}
    for name, cases in groups.items():
        folders[name] = root / "cases" / name
        _prepare(cases[0], folders[name], baseline, result)
    servers: Queue[_Forks] = Queue()
    for i in range(2):
        servers.put(_Forks(env, root / f"forks-{i}.log"))

    def run(name: str) -> list[Ran]:
        forks = servers.get()
        try:
            return _run_group(groups[name], folders[name], root / "commands" / f"{name}.json", forks)
        finally:
            servers.put(forks)

    try:
        with ThreadPoolExecutor(max_workers=2) as pool:
            futures = {name: pool.submit(run, name) for name in groups}
            out = {}
            for name, cases in groups.items():
                for case, r in zip(cases, futures[name].result(), strict=True):
                    out[case.id] = (folders[name], r)
            return out
    finally:
        while not servers.empty():
            servers.get().close()


def test_the_corpus_is_large_and_varied() -> None:
    assert len(CASES) >= 60
    assert len({c.id for c in CASES}) == len(CASES)
    commands = {c.argv[0] for c in CASES}
    assert {"check", "search", "replay", "report", "show", "campaign", "simulate"} <= commands


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_input(case: Case, ran) -> None:
    folder, r = ran[case.id]
    assert r.code is not None, f"{case.id}: {r.err}"
    assert "Traceback" not in r.err and "Traceback" not in r.out, r.err[-2000:]
    assert r.code == case.code, f"exit {r.code}, expected {case.code}\nstdout: {r.out[-1500:]}\nstderr: {r.err[-1500:]}"
    if case.code == 2:
        lines = r.err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), r.err[-2000:]
        assert len(lines[0]) < 1000, lines[0][:300]
        for w in case.says:
            assert w in lines[0], f"{w!r} not in {lines[0]!r}"
    elif case.code == 1 and case.argv[0] == "replay":  # (check's exit 1 is a failing check: its case says how)
        mismatches = [line for line in r.out.splitlines() if line.startswith("MISMATCH: ")]
        assert mismatches and any(w in mismatches[0] for w in case.says), r.out[-1500:]
        assert "REPRODUCED" not in r.out
    assert "\x1b" not in r.out + r.err
    # nothing created or changed outside out/ (and the files a case may create)
    outside = {k: v for k, v in r.after.items() if not k.startswith("out/") and k not in case.creates}
    assert outside == {k: v for k, v in r.before.items() if not k.startswith("out/")}
    if case.check is not None:
        case.check(folder, r.out, r.err)
