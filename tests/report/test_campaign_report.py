"""The campaign report from hand-made run records: discovery curves, discovery.png, report.html."""

from __future__ import annotations

from html.parser import HTMLParser

import numpy as np
import pytest
from PIL import Image

from cellstress.report.campaign import CampaignOptions, discovery_curves, write_campaign_report

RECORDS = (
    [{"cell": "s1-scanner-width", "searcher": "random", "seed": s, "budget": 200, "found": f, "episodes": e}
     for s, (f, e) in enumerate([(True, 50), (False, 200), (True, 150), (False, 200)])]
    + [{"cell": "s1-scanner-width", "searcher": "mcts", "seed": s, "budget": 200, "found": True, "episodes": e}
       for s, e in enumerate([10, 20, 30, 40])]
    + [{"cell": "s3-fence-gap", "searcher": "random", "seed": s, "budget": 100, "found": True, "episodes": 5 + s}
       for s in range(3)]
    + [{"cell": "s3-fence-gap", "searcher": "mcts", "seed": 0, "budget": 100, "found": False, "episodes": 100}]
)


def test_discovery_curves():
    c = discovery_curves(RECORDS)
    assert list(c) == ["s1-scanner-width", "s3-fence-gap"]
    r = c["s1-scanner-width"]["random"]
    assert len(r) == 200
    assert r[48] == 0.0 and r[49] == 0.25 and r[149] == 0.5 and r[-1] == 0.5  # failed runs never count
    assert c["s1-scanner-width"]["mcts"][39] == 1.0
    assert np.all(np.diff(c["s3-fence-gap"]["random"]) >= 0) and c["s3-fence-gap"]["mcts"].max() == 0.0


def test_campaign_report_files(tmp_path):
    table = "cell              searcher  found  mean episodes\ns1-scanner-width  random    2/4    150.0\n"
    files = write_campaign_report(RECORDS, table, tmp_path)
    opts = CampaignOptions()
    with Image.open(files.discovery) as img:
        assert img.size == (round(opts.panel_width * 2 * opts.dpi), round(opts.height * opts.dpi))
        assert float(np.asarray(img.convert("L"), float).std()) > 8.0
    raw = files.html.read_text(encoding="utf-8")
    tags: list[tuple[str, dict]] = []

    class P(HTMLParser):
        def handle_starttag(self, tag, attrs):
            tags.append((tag, dict(attrs)))

    P().feed(raw)
    assert [a["src"][:22] for t, a in tags if t == "img"] == ["data:image/png;base64,"]
    assert "script" not in [t for t, _ in tags] and "http" not in raw
    assert "s1-scanner-width  random    2/4" in raw  # the table, verbatim
    assert "2/4" in raw and "4/4" in raw and "0/1" in raw


def test_campaign_records_are_checked(tmp_path):
    with pytest.raises(ValueError, match="lacks episodes"):
        write_campaign_report([{"cell": "c", "searcher": "s", "seed": 0, "budget": 1, "found": False}], "", tmp_path)
