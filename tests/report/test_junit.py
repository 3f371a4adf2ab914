"""JUnit XML reports (``--junit FILE`` on check, search and verify): the schema's structure, text from hostile
files escaped, the same bytes for the same inputs, and one test case per check row, hazard class or verdict."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from importlib import resources
from pathlib import Path

import pytest
import yaml
from junit_schema import validate_junit

from cellstress.cli import main
from cellstress.core.text import for_xml
from cellstress.report.junit import ERROR, FAILED, PASSED, SKIPPED, Case, Suite, junit_xml

HOSTILE = 'a<b>&c "q" \'s\' ]]> end'  # what a cell's names may hold (names are printable, one line)
CONTROL = "x\x00y\x1b[31mz\x7f\x85\u202e\ud800\ufffe\uffff\ttab\nline"  # what other text might


def _cases() -> tuple[Case, ...]:
    return (Case("ok " + HOSTILE, "k." + HOSTILE, PASSED, output=CONTROL),
            Case("bad " + HOSTILE, "k", FAILED, HOSTILE + CONTROL, CONTROL),
            Case("broken", "k", ERROR, "undecided", "text"),
            Case("skip", "k", SKIPPED, "not run"))


def test_the_validator_can_fail():
    good = junit_xml([Suite("s", _cases())]).encode()
    validate_junit(good)
    wrong_count = good.replace(b'failures="1"', b'failures="2"', 1)
    no_classname = good.replace(b' classname="k"', b"", 1)
    two_outcomes = good.replace(b"<skipped ", b'<failure message="m"/><skipped ', 1)
    late_outcome = junit_xml([Suite("s", (Case("c", "k", FAILED, "m", "t", "out"),))]).encode().replace(
        b"<failure", b"<system-out>x</system-out><failure", 1)
    for bad in (wrong_count, no_classname, two_outcomes, late_outcome):
        with pytest.raises(AssertionError):
            validate_junit(bad)


def test_hostile_text_is_escaped_and_round_trips():
    data = junit_xml([Suite("suite " + HOSTILE, _cases())]).encode("utf-8")
    root = validate_junit(data)  # a parser would refuse NUL, U+FFFE or a lone surrogate anywhere in the file
    assert b"]]>" not in data and b"\x00" not in data and b"\x1b" not in data
    suite = root[0]
    assert suite.get("name") == "suite " + HOSTILE
    cases = list(suite)
    assert [c.get("name") for c in cases] == ["ok " + HOSTILE, "bad " + HOSTILE, "broken", "skip"]
    assert cases[0].get("classname") == "k." + HOSTILE
    shown = "x\\x00y\\x1b[31mz\\x7f\\x85\\u202e\\ud800\\ufffe\\uffff\ttab\nline"
    assert cases[0].find("system-out").text == shown
    failure = cases[1].find("failure")
    assert failure.get("message") == HOSTILE + shown  # tab and line feed kept as character references
    assert failure.text == shown
    assert cases[2].find("error").get("message") == "undecided"
    assert cases[3].find("skipped").get("message") == "not run"
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors"), suite.get("skipped")) == ("4", "1", "1",
                                                                                                       "1")
    assert for_xml("]]>") == "]]&gt;"


@pytest.fixture(scope="module")
def hostile_cell(tmp_path_factory) -> Path:
    """The baseline with its name and its scanner's name full of XML's special characters, and the scanner's
    field too short (so that the check fails on a row named by them)."""
    text = resources.files("cellstress.cell").joinpath("builtin", "s1-scanner-width.yaml").read_text(encoding="utf-8")
    doc = yaml.safe_load(text)
    doc["name"] = "cell " + HOSTILE
    scanner = next(d for d in doc["devices"] if d["type"] == "laser-scanner")
    scanner["name"] = "scanner " + HOSTILE
    path = tmp_path_factory.mktemp("hostile") / "cell.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def test_check_writes_one_case_per_row(hostile_cell, tmp_path, capsys):
    out = tmp_path / "reports" / "check.xml"
    assert main(["check", str(hostile_cell), "--junit", str(out)]) == 1
    printed = capsys.readouterr().out
    data = out.read_bytes()
    root = validate_junit(data)
    suite = root[0]
    assert suite.get("name") == "cellstress check cell " + HOSTILE
    failed = [c.get("name") for c in suite if c.find("failure") is not None]
    assert failed == ["scanner " + HOSTILE]
    fail_line = next(line for line in printed.splitlines() if line.startswith("FAIL:"))
    assert fail_line.endswith(f"({', '.join(failed)})")  # the same rows fail as check says
    assert int(suite.get("tests")) >= 8  # program, devices, reach, openings, ... (every row, not only failures)
    assert main(["check", str(hostile_cell), "--junit", str(tmp_path / "again.xml")]) == 1
    assert (tmp_path / "again.xml").read_bytes() == data  # the same inputs give the same bytes


def test_check_junit_on_a_passing_cell(tmp_path):
    out = tmp_path / "baseline.xml"
    assert main(["check", "baseline", "--junit", str(out)]) == 0
    root = validate_junit(out.read_bytes())
    assert root.get("failures") == "0" and int(root.get("tests")) >= 8


def test_a_junit_path_that_cannot_be_written_is_a_user_error(tmp_path, capsys):
    assert main(["check", "baseline", "--junit", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --junit") and "directory" in err[0]


def test_search_cases(tmp_path):
    found = tmp_path / "found.xml"
    args = ["search", "s3-fence-gap", "--searcher", "plan", "--budget", "40", "--seed", "0", "--no-report"]
    assert main([*args, "--out", str(tmp_path / "s3"), "--junit", str(found)]) == 0
    suite = validate_junit(found.read_bytes())[0]
    assert [c.get("classname") for c in suite] == ["search.hazard"]
    assert suite[0].find("failure") is not None
    distinct = tmp_path / "distinct.xml"
    assert main([*args, "--until", "budget", "--distinct", "--out", str(tmp_path / "s3d"),
                 "--junit", str(distinct)]) == 0
    suite = validate_junit(distinct.read_bytes())[0]
    from cellstress.searchers.result import SearchResult

    res = SearchResult.load(tmp_path / "s3d")
    assert len(suite) == len(res.distinct) >= 1 and suite.get("failures") == str(len(res.distinct))
    none = tmp_path / "none.xml"
    assert main(["search", "baseline", "--searcher", "random", "--budget", "8", "--no-report",
                 "--out", str(tmp_path / "b"), "--junit", str(none)]) == 0
    suite = validate_junit(none.read_bytes())[0]
    assert [(c.get("name"), c.find("failure")) for c in suite] == [("no hazard found", None)]
    assert "not a proof" in suite[0].find("system-out").text


def test_verify_cases(tmp_path):
    safe = tmp_path / "safe.xml"
    assert main(["verify", "baseline", "--phases", "cell", "--horizon", "2", "--out", str(tmp_path / "v0"),
                 "--junit", str(safe)]) == 0
    suite = validate_junit(safe.read_bytes())[0]
    assert [c.get("name") for c in suite] == ["verdict: PROVED-SAFE"] and suite.get("failures") == "0"
    unsafe = tmp_path / "unsafe.xml"
    assert main(["verify", "s1-scanner-width", "--phases", "cell", "--horizon", "5", "--out", str(tmp_path / "v1"),
                 "--junit", str(unsafe)]) == 1
    data = unsafe.read_bytes()
    suite = validate_junit(data)[0]
    from cellstress.verifier.records import VerifyResult

    res = VerifyResult.model_validate_json((tmp_path / "v1" / "verify.json").read_bytes())
    assert [c.get("classname") for c in suite] == ["verify.verdict"] + ["verify.witness"] * len(res.classes)
    assert suite.get("failures") == str(1 + len(res.classes)) and len(res.classes) >= 1
    assert ET.fromstring(data)[0][0].get("name") == "verdict: UNSAFE"
