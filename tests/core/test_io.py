"""core.io: atomic writes that never follow a link planted in an output folder, bounded reads, and JSON keys
given twice (issue 29)."""

from __future__ import annotations

import os
import stat

import pytest

from cellstress.core.io import (
    InputFileError,
    OutputPathError,
    atomic_write,
    duplicate_json_key,
    read_input_bytes,
    write_in_folder,
)


@pytest.fixture
def victim(tmp_path):
    d = tmp_path / "elsewhere"
    d.mkdir()
    (d / "result.json").write_text("keep me\n")
    return d


def test_a_link_at_the_file_is_replaced_not_followed(tmp_path, victim):
    out = tmp_path / "out"
    out.mkdir()
    (out / "result.json").symlink_to(victim / "result.json")
    atomic_write(out / "result.json", b"new\n")
    assert (victim / "result.json").read_text() == "keep me\n"
    assert not (out / "result.json").is_symlink() and (out / "result.json").read_text() == "new\n"


def test_new_files_get_the_usual_permissions(tmp_path):
    old = os.umask(0o027)
    try:
        atomic_write(tmp_path / "a.txt", b"x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a.txt").stat().st_mode) == 0o640
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]  # no temporary file left


@pytest.mark.parametrize("depth", [1, 2])
def test_a_link_planted_as_a_folder_inside_out_is_refused(tmp_path, victim, depth):
    """The verify witness of issue 29: out/witness-01 -> elsewhere put result.json outside --out."""
    out = tmp_path / "out"
    (out / "a").mkdir(parents=True)
    planted = out / "witness-01" if depth == 1 else out / "a" / "witness-01"
    planted.symlink_to(victim)
    with pytest.raises(OutputPathError) as err:
        write_in_folder(planted, "result.json", "new\n", inside=out)
    assert str(err.value).startswith(f"{planted}: is a symbolic link")
    assert sorted(p.name for p in victim.iterdir()) == ["result.json"]
    assert (victim / "result.json").read_text() == "keep me\n"


def test_a_file_planted_as_a_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "witness-01").write_text("x")
    with pytest.raises(OutputPathError, match="is not a folder"):
        write_in_folder(out / "witness-01", "result.json", "new\n", inside=out)


def test_folders_inside_out_are_made(tmp_path):
    out = tmp_path / "out"
    path = write_in_folder(out / "a" / "b", "r.json", "x\n", inside=out)
    assert path == out / "a" / "b" / "r.json" and path.read_text() == "x\n"
    assert write_in_folder(out / "a" / "b", "r.json", "y\n", inside=out).read_text() == "y\n"


def test_the_output_folder_itself_may_be_a_link(tmp_path, victim):
    """--out is the user's choice: a link there is followed (only what lies below it is ours)."""
    (tmp_path / "out").symlink_to(victim)
    write_in_folder(tmp_path / "out" / "w", "r.json", "x\n", inside=tmp_path / "out")
    assert (victim / "w" / "r.json").read_text() == "x\n"


def test_reading_without_following(tmp_path, victim):
    (tmp_path / "link.json").symlink_to(victim / "result.json")
    assert read_input_bytes(tmp_path / "link.json") == b"keep me\n"
    with pytest.raises(InputFileError, match="is a symbolic link"):
        read_input_bytes(tmp_path / "link.json", follow=False)


@pytest.mark.parametrize(("text", "key"), [
    ('{"a": 1, "b": 2}', None),
    ('{"a": 1, "a": 2}', "a"),
    ('{"x": [{"k": 1}, {"k": 2, "k": 3}]}', "k"),
    ('{"a": 1', None),  # not JSON: its own parser says so
    ("[" * 100_000 + "]" * 100_000, None),  # too deep for Python's parser: the strict parser reports it
    ('[{"": 0, "": 1}]', ""),
])
def test_duplicate_json_key(text, key):
    assert duplicate_json_key(text) == key


def test_file_digest_streams_regular_files_only(tmp_path):
    import hashlib

    from cellstress.core.io import file_digest

    data = bytes(range(256)) * 5000
    (tmp_path / "a.bin").write_bytes(data)
    assert file_digest(tmp_path / "a.bin") == (len(data), hashlib.sha256(data).hexdigest())
    with pytest.raises(InputFileError, match="too large"):
        file_digest(tmp_path / "a.bin", max_bytes=1000)
    os.mkfifo(tmp_path / "fifo")
    with pytest.raises(InputFileError, match="not a regular file"):
        file_digest(tmp_path / "fifo")
    with pytest.raises(InputFileError, match="not a regular file"):
        file_digest(tmp_path)
    with pytest.raises(InputFileError, match="no such file"):
        file_digest(tmp_path / "none")
