"""Severity first (issue 28): hazards carry their severity, findings are listed worst first and contacts while the
robot creeps after the others, in result files (checked strictly when read back, replayable, old files too), on
the command line and in verify's witnesses."""

from __future__ import annotations

import json
import math

import pytest

from cellstress.analysis.replay import check_result
from cellstress.criteria.iso15066 import CREEP_SPEED, HEAD_REGIONS, REGIONS, transient_limit
from cellstress.searchers import search
from cellstress.searchers.common import SearchError
from cellstress.searchers.result import SearchResult
from cellstress.searchers.severity import rank, severity
from cellstress.sim.simulator import Simulator
from cellstress.verifier.run import verify_cell


def test_creep_speed_is_the_slowest_harmful_transient_contact():
    # by hand from ISO/TS 15066 Tables A.2 and A.3: the lower legs, 2 x 130 N / sqrt(75 kg x 60 N/mm)
    assert CREEP_SPEED == pytest.approx(260.0 / math.sqrt(75.0 * 60_000.0))
    for region, (_, k, m) in REGIONS.items():
        if region not in HEAD_REGIONS:  # however heavy the robot, F <= v sqrt(m_H k) stays within the limit
            assert CREEP_SPEED * math.sqrt(m * k * 1000.0) <= transient_limit(region) + 1e-9


def test_severity_and_its_order():
    fast, slow, creep = severity(0.8, None), severity(0.3, None), severity(0.05, None)
    assert not fast.creeping and creep.creeping and creep.force_ratio is None
    assert sorted([creep, slow, fast], key=rank) == [fast, slow, creep]
    force = severity(0.5, {"ratio": 1.7, "reason": "..."})
    head = severity(0.5, {"ratio": 0.2, "reason": "face contact while the robot moves"})
    assert force.force_ratio == 1.7 and head.force_ratio == 1.0  # a head contact counts at least its limit
    assert sorted([head, force], key=rank) == [force, head]
    assert severity(None, None).v_R == 0.0


@pytest.fixture(scope="module")
def distinct_s3():
    sim = Simulator("s3-fence-gap")
    return sim, search(sim, "evolve", 150, 3, until="budget", distinct=True)


def test_distinct_hazards_are_listed_worst_first_with_the_replayed_speed(distinct_s3, tmp_path):
    sim, res = distinct_s3
    hs = res.distinct
    assert len(hs) >= 3
    assert [rank(h.severity) for h in hs] == sorted(rank(h.severity) for h in hs)
    assert [h.episode for h in hs] != sorted(h.episode for h in hs) or len({rank(h.severity) for h in hs}) == 1
    for h in hs:
        assert h.severity.v_R == h.v_R and h.severity.creeping == (h.v_R < CREEP_SPEED)
    assert res.hazard.severity.v_R == res.hazard.v_R
    path = res.write(tmp_path)
    back = SearchResult.load(path)  # read back strictly, with its severities
    assert back.to_json() == res.to_json()
    assert check_result(back, 0, search_again=True).reproduced


def test_a_file_written_before_severities_still_replays(distinct_s3, tmp_path):
    """Files of earlier versions carry no severity and list the classes in the order found."""
    _, res = distinct_s3
    doc = json.loads(res.to_json())
    doc["hazard"].pop("severity")
    for d in doc["distinct"]:
        d.pop("severity")
    doc["distinct"].sort(key=lambda d: d["episode"])
    (tmp_path / "result.json").write_text(json.dumps(doc))
    old = SearchResult.load(tmp_path / "result.json")
    assert old.hazard.severity is None
    check = check_result(old, 1, search_again=True)
    assert check.reproduced, check.problems


def test_a_forged_severity_is_a_mismatch(distinct_s3, tmp_path):
    _, res = distinct_s3
    doc = json.loads(res.to_json())
    doc["hazard"]["severity"]["v_R"] = 0.001
    (tmp_path / "result.json").write_text(json.dumps(doc))
    check = check_result(SearchResult.load(tmp_path / "result.json"), search_again=False)
    assert any("severity.v_R" in p for p in check.problems)
    doc["hazard"]["severity"]["v_R"] = "fast"
    (tmp_path / "result.json").write_text(json.dumps(doc))
    with pytest.raises(SearchError, match="hazard.severity.v_R"):
        SearchResult.load(tmp_path / "result.json")


def test_verify_numbers_its_classes_worst_first(tmp_path):
    sim = Simulator("s1-scanner-width")
    res = verify_cell(sim, horizon=5, phases="cell", out=tmp_path)
    assert len(res.classes) >= 2
    assert [rank(w.severity) for w in res.classes] == sorted(rank(w.severity) for w in res.classes)
    for w in res.classes:  # each witness file carries the same severity, and replays
        witness = SearchResult.load(tmp_path / w.file)
        assert witness.hazard.severity == w.severity
    # the class counts of the sub-trees point at the renumbered classes
    counted = {c.klass: 0 for c in res.subtrees[0].classes}
    for s in res.subtrees:
        for c in s.classes:
            counted[c.klass] += c.sequences
    assert counted == {i: w.sequences for i, w in enumerate(res.classes)}
