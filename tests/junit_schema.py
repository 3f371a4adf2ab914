"""A hand-written check of a JUnit XML file against the structure of the schema CI servers commonly validate
against (Jenkins' and Ant's ``junit-10.xsd``), since no XSD validator is installed (lxml and xmlschema are not
dependencies, and one is not worth adding for a test). What it checks, as that schema says:

* the root is ``testsuites`` (attributes ``tests failures errors skipped time`` where given: counts are
  non-negative integers, time a decimal), holding only ``testsuite`` elements;
* a ``testsuite`` has ``name``, ``tests``, ``failures``, ``errors``, ``skipped`` (integers) and ``time``
  (decimal); its children are ``properties``, ``testcase``, ``system-out``, ``system-err`` only;
* a ``testcase`` has ``name``, ``classname`` and ``time`` (decimal); its children are at most one of
  ``failure``/``error``/``skipped`` (``message`` and ``type`` attributes only, text inside), then ``system-out``
  and ``system-err``, in that order;
* the counts equal the children's: tests = test cases, failures = ``failure`` elements, and so on, per suite and
  summed over the suites.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

DECIMAL = re.compile(r"^-?\d+(\.\d+)?$")
COUNTS = ("tests", "failures", "errors", "skipped")
OUTCOMES = ("failure", "error", "skipped")


def _integer(el: ET.Element, key: str) -> int:
    value = el.get(key)
    assert value is not None, f"<{el.tag}> lacks {key}"
    assert re.fullmatch(r"\d+", value), f"<{el.tag} {key}={value!r}>: not a non-negative integer"
    return int(value)


def _decimal(el: ET.Element, key: str) -> None:
    value = el.get(key)
    assert value is not None, f"<{el.tag}> lacks {key}"
    assert DECIMAL.match(value), f"<{el.tag} {key}={value!r}>: not a decimal"


def _case(tc: ET.Element) -> str | None:
    """The case's outcome element's tag (None: it passed), after checking its structure."""
    assert tc.tag == "testcase"
    assert set(tc.attrib) <= {"name", "classname", "time", "assertions", "file", "line"}, tc.attrib
    assert tc.get("name"), "a testcase needs a name"
    assert tc.get("classname") is not None, "a testcase needs a classname"
    _decimal(tc, "time")
    tags = [c.tag for c in tc]
    outcomes = [t for t in tags if t in OUTCOMES]
    assert len(outcomes) <= 1, f"testcase {tc.get('name')!r}: {outcomes}"
    order = {"failure": 0, "error": 0, "skipped": 0, "system-out": 1, "system-err": 2}
    assert all(t in order for t in tags), tags
    assert [order[t] for t in tags] == sorted(order[t] for t in tags), f"children out of order: {tags}"
    for c in tc:
        if c.tag in OUTCOMES:
            assert set(c.attrib) <= {"message", "type"}, c.attrib
            assert len(c) == 0
    return outcomes[0] if outcomes else None


def validate_junit(data: bytes) -> ET.Element:
    """Parse and check a JUnit XML file (AssertionError naming what is wrong); returns its root."""
    assert data.startswith(b'<?xml version="1.0" encoding="UTF-8"?>'), data[:60]
    root = ET.fromstring(data)
    assert root.tag == "testsuites", root.tag
    totals = dict.fromkeys(COUNTS, 0)
    for suite in root:
        assert suite.tag == "testsuite", suite.tag
        assert suite.get("name"), "a testsuite needs a name"
        declared = {k: _integer(suite, k) for k in COUNTS}
        _decimal(suite, "time")
        assert all(c.tag in ("properties", "testcase", "system-out", "system-err") for c in suite)
        outcomes = [_case(tc) for tc in suite if tc.tag == "testcase"]
        found = {"tests": len(outcomes), "failures": outcomes.count("failure"), "errors": outcomes.count("error"),
                 "skipped": outcomes.count("skipped")}
        assert declared == found, f"suite {suite.get('name')!r}: declares {declared}, holds {found}"
        for k in COUNTS:
            totals[k] += found[k]
    for k in COUNTS:
        if root.get(k) is not None:
            assert _integer(root, k) == totals[k], f"<testsuites {k}>: {root.get(k)} != {totals[k]}"
    if root.get("time") is not None:
        _decimal(root, "time")
    return root
