"""Files in and out: canonical JSON, atomic writes, and reading files that other people send.

Every output is written atomically (a temporary file in the same folder, then ``os.replace``): a crash leaves
the old file or the new one, never a mix, and a symbolic link planted at the target is replaced, not followed.
Inputs (cell files, result files) are untrusted: only regular files are read, and never more than
``MAX_INPUT_BYTES``, so a FIFO, a device or a huge file gives one clear error instead of a hang.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import secrets
import stat
from pathlib import Path
from typing import Any

from cellstress.core.errors import CellstressError

MAX_INPUT_BYTES = 10 * 1024 * 1024  # no cell or result file of ours comes near this (a result is ~1 MB)


class InputFileError(Exception):
    """A file that cannot be read as input: ``problem`` says why in a few words (the caller names the file)."""

    def __init__(self, problem: str):
        self.problem = problem
        super().__init__(problem)


def json_ready(obj: Any) -> Any:
    """Plain JSON values: non-finite floats -> null, tuples -> lists, numpy scalars -> Python numbers."""
    if isinstance(obj, bool) or obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_ready(v) for v in obj]
    if hasattr(obj, "item"):  # numpy scalar
        return json_ready(obj.item())
    raise TypeError(f"not JSON-ready: {type(obj).__name__}")


def canonical_json(doc: Any) -> str:
    """``doc`` as the text our JSON files hold: sorted keys, one-space indent, no NaN, a final newline.

    Floats use Python's shortest round-trip repr, so the same values always give the same bytes."""
    return json.dumps(json_ready(doc), sort_keys=True, indent=1, allow_nan=False) + "\n"


def json_line(record: Any) -> str:
    """A record as one line of text (no newline): sorted keys, no spaces, no NaN."""
    return json.dumps(json_ready(record), sort_keys=True, separators=(",", ":"), allow_nan=False)


def atomic_write(path: Path, data: bytes) -> None:
    """Replace ``path`` by ``data`` atomically (a crash leaves the old or the new file, never a mix).

    The new file gets the permissions a plain ``open`` would give it (0666 less the umask)."""
    path = Path(path)
    fd = os.open(path.parent if str(path.parent) else ".", os.O_RDONLY | _DIRECTORY)
    try:
        _atomic_write_at(fd, path.name, data)
    finally:
        os.close(fd)


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write(path, text.encode("utf-8"))


class OutputPathError(CellstressError):
    """A folder cellstress would write into is a symbolic link (or a file) planted inside an output folder."""


_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


def _atomic_write_at(dir_fd: int, name: str, data: bytes) -> None:
    """Write ``name`` in the folder open as ``dir_fd``: a new file of a random name, then renamed over ``name``
    (a link planted at ``name`` is replaced, not followed; nothing is looked up by path outside the folder)."""
    for _ in range(100):
        tmp = f".{name}-{secrets.token_hex(6)}.tmp"
        try:  # the mode is masked by the umask, as for a plain open
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o666, dir_fd=dir_fd)
            break
        except FileExistsError:
            continue
    else:
        raise FileExistsError(f"no free temporary name for {name}")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
    except BaseException:
        try:
            os.unlink(tmp, dir_fd=dir_fd)
        except FileNotFoundError:
            pass
        raise


def _open_below(root: Path, parts: tuple[str, ...]) -> int:
    """A descriptor of the folder ``root/parts...``, each part made if missing and opened without following a
    link, so nothing planted below ``root`` can send a write elsewhere; ``root`` itself is followed (the user
    named it)."""
    fd = os.open(root, os.O_RDONLY | _DIRECTORY)
    where = root
    try:
        for part in parts:
            where = where / part
            if part in ("", ".", "..") or "/" in part:
                raise OutputPathError(f"{where}: not a plain folder name")
            try:
                os.mkdir(part, 0o777, dir_fd=fd)
            except FileExistsError:
                pass
            try:
                sub = os.open(part, os.O_RDONLY | _DIRECTORY | _NOFOLLOW, dir_fd=fd)
            except OSError:
                kind = "a symbolic link" if os.path.islink(where) else "not a folder"
                raise OutputPathError(f"{where}: is {kind}; cellstress never writes through a link or over a file "
                                      f"inside its output folder {root} (remove it, or use another folder)") from None
            os.close(fd)
            fd = sub
    except BaseException:
        os.close(fd)
        raise
    return fd


def write_in_folder(folder: str | Path, name: str, text: str, *, inside: str | Path | None = None) -> Path:
    """Write ``folder/name`` atomically (the folder made if missing); returns its path.

    ``inside``: an output folder the user chose, which ``folder`` lies in: the folders between are made or
    opened without following a symbolic link (OutputPathError for a link or a file planted there)."""
    out = Path(folder)
    if inside is None:
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out / name, text)
        return out / name
    root = Path(inside)
    root.mkdir(parents=True, exist_ok=True)
    fd = _open_below(root, out.relative_to(root).parts)
    try:
        _atomic_write_at(fd, name, text.encode("utf-8"))
    finally:
        os.close(fd)
    return out / name


def _umask() -> int:
    # os.umask can only be read by setting it; set it back at once (a process-wide value, read here only)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def read_input_bytes(path: str | Path, max_bytes: int = MAX_INPUT_BYTES, *, follow: bool = True) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``; InputFileError (a short reason) otherwise.

    The file is opened without blocking and checked with fstat before anything is read, so a FIFO or a
    device never blocks and nothing beyond the cap is ever read. ``follow=False``: a symbolic link at ``path``
    itself is refused (for files cellstress wrote into an output folder, where a link can only be planted)."""
    p = Path(path).expanduser()
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(p, flags)
    except FileNotFoundError:
        raise InputFileError("no such file") from None
    except IsADirectoryError:
        raise InputFileError("is a directory, not a file") from None
    except OSError as exc:
        if not follow and os.path.islink(p):
            raise InputFileError("is a symbolic link (cellstress does not follow links in its output folders)") \
                from None
        raise InputFileError(f"cannot be read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise InputFileError("is a directory, not a file")
        if not stat.S_ISREG(st.st_mode):
            raise InputFileError("is not a regular file (a pipe, a device or a socket)")
        if st.st_size > max_bytes:
            raise InputFileError(f"is too large ({st.st_size:,} bytes; at most {max_bytes:,})")
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:  # it grew while we read it
                raise InputFileError(f"is too large (more than {max_bytes:,} bytes)")
        return b"".join(chunks)
    except OSError as exc:
        raise InputFileError(f"cannot be read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)


class _Duplicate(Exception):
    def __init__(self, key: str):
        self.key = key


def _no_repeats(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    seen: dict[str, Any] = {}
    for k, v in pairs:
        if k in seen:
            raise _Duplicate(k)
        seen[k] = v
    return seen


def duplicate_json_key(raw: bytes | str) -> str | None:
    """The first key that a JSON object of ``raw`` repeats, or None (also for text that is not JSON: its
    parser says what is wrong). A repeated key is refused in every JSON file cellstress reads: parsers keep
    one of the two values, and which one differs between programs, so two readers could see two files."""
    try:
        json.loads(raw, object_pairs_hook=_no_repeats)
    except _Duplicate as dup:
        return dup.key
    except (ValueError, RecursionError, UnicodeDecodeError):
        return None
    return None


MAX_HASHED_BYTES = 2**30  # a file a cell pulls in (a mesh, a trajectory): far above what its reader accepts


def file_digest(path: str | Path, max_bytes: int = MAX_HASHED_BYTES) -> tuple[int, str]:
    """(size in bytes, SHA-256) of a regular file, read in pieces (never whole into memory); InputFileError for
    anything else, before a byte is read, as ``read_input_bytes``."""
    try:
        fd = os.open(Path(path), os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise InputFileError("no such file") from None
    except OSError as exc:
        raise InputFileError(f"cannot be read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputFileError("is not a regular file (a pipe, a device, a socket or a folder)")
        if st.st_size > max_bytes:
            raise InputFileError(f"is too large ({st.st_size:,} bytes; at most {max_bytes:,})")
        h, total = hashlib.sha256(), 0
        while chunk := os.read(fd, 1 << 20):
            total += len(chunk)
            if total > max_bytes:
                raise InputFileError(f"is too large (more than {max_bytes:,} bytes)")
            h.update(chunk)
        return total, h.hexdigest()
    except OSError as exc:
        raise InputFileError(f"cannot be read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
