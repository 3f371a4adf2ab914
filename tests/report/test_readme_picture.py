"""The README's picture is what the README's command makes: run the command, compare with the committed file."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
from PIL import Image

from cellstress.cli import main

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_readme_picture_is_regenerated(tmp_path, capsys):
    section = README.split("## Reports", 1)[1].split("\n## ", 1)[0]
    picture = re.search(r"!\[[^\]]*\]\((docs/images/[^)]+\.png)\)", section).group(1)
    made_by = re.search(r"`(out/[^`]+\.png)` from the first command above", section).group(1)
    command = next(ln for ln in section.splitlines() if ln.startswith("cellstress search "))
    args = shlex.split(command)[1:]
    out_dir = args[args.index("--out") + 1]
    assert made_by.startswith(out_dir + "/")
    args[args.index("--out") + 1] = str(tmp_path / out_dir)
    assert main(args) == 0, capsys.readouterr().err
    made = tmp_path / made_by
    committed = ROOT / picture
    if made.read_bytes() == committed.read_bytes():
        return
    # another matplotlib or FreeType may rasterise text slightly differently: then the pixels must still agree
    a = np.asarray(Image.open(made).convert("RGB"), dtype=float)
    b = np.asarray(Image.open(committed).convert("RGB"), dtype=float)
    assert a.shape == b.shape
    assert np.abs(a - b).mean() < 2.0
    assert (np.abs(a - b).max(axis=2) > 64).mean() < 0.01
