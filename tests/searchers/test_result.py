"""Result files from other people (searchers.result): lists that disagree with the episodes played, and keys
given twice, are refused with one line naming the file and the field (issue 29)."""

from __future__ import annotations

import json

import pytest

from cellstress.searchers import SearchError, search
from cellstress.searchers.result import SearchResult


@pytest.fixture(scope="module")
def doc(tmp_path_factory) -> dict:
    """A real result: random search on s1, the whole budget of 40 (every list filled)."""
    res = search("s1-scanner-width", "random", 40, 0, until="budget")
    assert res.found and res.episodes == 40
    return json.loads(res.to_json())


def _load(tmp_path, doc: dict | None = None, text: str | None = None) -> SearchResult:
    path = tmp_path / "result.json"
    path.write_text(text if text is not None else json.dumps(doc))
    return SearchResult.load(path)


def test_the_real_file_loads(tmp_path, doc):
    assert _load(tmp_path, doc).episodes == 40


@pytest.mark.parametrize(("change", "says"), [
    (lambda d: d.update(risk_per_episode=[0.1] * 600_000), "risk_per_episode: lists 600,000 values for 40 episodes"),
    (lambda d: d.update(risk_per_episode=d["risk_per_episode"][:-1]), "risk_per_episode: lists 39 values"),
    (lambda d: d.update(episodes=41), "episodes: 41 played, more than the budget of 40"),
    (lambda d: d.update(distinct_sequences=41), "distinct_sequences: 41, more than the 40 episodes"),
    (lambda d: d.update(hazards=d["hazards"] * 41), "hazards: lists"),
    (lambda d: d["hazards"][0].update(episode=41), "hazards[0].episode: episode 41 of 40"),
    (lambda d: d["top"][0].update(episode=1000), "top[0].episode: episode 1,000 of 40"),
])
def test_lists_must_agree_with_the_episodes(tmp_path, doc, change, says):
    d = json.loads(json.dumps(doc))
    change(d)
    with pytest.raises(SearchError) as err:
        _load(tmp_path, d)
    assert str(err.value).startswith(f"{tmp_path / 'result.json'}: not a cellstress result file: {says}"), err.value


@pytest.mark.parametrize("key", ["budget", "seed", "x"])
def test_a_key_given_twice_is_refused(tmp_path, doc, key):
    text = json.dumps(doc)
    if key == "x":  # inside a nested object: the hazard's trace row
        text = text.replace('"d_HR": ', '"d_HR": 0.5, "d_HR": ', 1)
        key = "d_HR"
    else:
        text = text.replace(f'"{key}": ', f'"{key}": 1, "{key}": ', 1)
    with pytest.raises(SearchError) as err:
        _load(tmp_path, text=text)
    assert f"the key '{key}' appears twice in one object" in str(err.value)


def test_the_files_the_cell_read_are_recorded(doc):
    files = doc["cell"]["files"]
    assert files[0] == {"use": "cell", "path": "cellstress:cell/builtin/s1-scanner-width.yaml",
                        "bytes": files[0]["bytes"], "sha256": doc["cell"]["sha256"]}
    assert [f["use"] for f in files[1:3]] == ["robot.urdf", "robot.urdf mesh"]


@pytest.mark.parametrize(("change", "says"), [
    (lambda fs: fs.extend([fs[0]] * 10_001), "cell.files: Tuple should have at most 10000 items"),
    (lambda fs: fs[1].update(sha256="z" * 64), "cell.files[1].sha256: String should match pattern"),
    (lambda fs: fs[1].update(path="a\x1b[2Jb"), "cell.files[1].path: String should match pattern"),
    (lambda fs: fs[1].update(bytes=-1), "cell.files[1].bytes: Input should be greater than or equal to 0"),
    (lambda fs: fs[1].update(bytes="12"), "cell.files[1].bytes: Input should be a valid integer"),
    (lambda fs: fs[1].update(evil=1), "cell.files[1].evil: Extra inputs are not permitted"),
])
def test_recorded_files_are_checked(tmp_path, doc, change, says):
    d = json.loads(json.dumps(doc))
    change(d["cell"]["files"])
    with pytest.raises(SearchError) as err:
        _load(tmp_path, d)
    assert f"not a cellstress result file: {says}" in str(err.value), err.value


def test_a_file_without_the_list_still_loads(tmp_path, doc):
    """Files written before issue 29 make no claim about the files: they load, and the list stays absent."""
    d = json.loads(json.dumps(doc))
    del d["cell"]["files"]
    res = _load(tmp_path, d)
    assert res.cell.files is None and "files" not in json.loads(res.to_json())["cell"]
