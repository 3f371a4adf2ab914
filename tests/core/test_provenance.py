"""core.provenance.file_changes: what replay says about the files a cell read (issue 29)."""

from __future__ import annotations

from cellstress.core.provenance import InputFile, file_changes


def _f(path: str, digest: str, use: str = "robot.urdf mesh", size: int = 10) -> InputFile:
    return InputFile(use=use, path=path, bytes=size, sha256=digest * 64)


def test_the_same_files_give_nothing():
    files = (_f("/a", "1"), _f("/b", "2"))
    assert file_changes(files, files) == []


def test_each_change_is_named_by_its_file():
    recorded = (_f("/a", "1"), _f("/b", "2"), _f("/c", "3"))
    now = (_f("/a", "1"), _f("/b", "4", size=11), _f("/d", "5", use="robot.urdf"))
    assert file_changes(recorded, now) == [
        "/b (robot.urdf mesh) has changed (sha256 222222222222 recorded, 444444444444 now; 10 bytes recorded, 11 now)",
        "/c (robot.urdf mesh) is no longer read by the cell",
        "/d (robot.urdf) is read by the cell now but was not recorded",
    ]
