"""Tests of agentchord.graph.loader."""

from __future__ import annotations

import gc
import json
from pathlib import Path

import pytest
import yaml

from agentchord.graph import GraphFileError, TaskGraph, dump_graph, load_graph
from agentchord.graph.loader import read_document

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"


def _write(tmp_path: Path, text: str, name: str = "g.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _problems(path: Path) -> list[str]:
    with pytest.raises(GraphFileError) as info:
        load_graph(path)
    assert info.value.path == path
    return info.value.problems


def test_loads_yaml() -> None:
    graph = load_graph(POUR)
    assert graph.task == "single_arm_pour_water"
    assert graph.objects == ["bottle", "cup"]
    assert len(graph.edge("e3_r_bottle_dropped").steps) == 2


@pytest.mark.parametrize("name", ["copy.yaml", "copy.yml", "copy.json"])
def test_round_trip_is_identity(tmp_path: Path, name: str) -> None:
    graph = load_graph(POUR)
    out = dump_graph(graph, tmp_path / name)
    assert load_graph(out) == graph
    # Dumping again gives the same text: the file form is stable.
    text = out.read_text()
    dump_graph(load_graph(out), out)
    assert out.read_text() == text


def test_yaml_dump_writes_steps_inline(tmp_path: Path) -> None:
    text = dump_graph(load_graph(POUR), tmp_path / "g.yaml").read_text()
    assert "actions: {right: {fn: move_to_obj, args: {obj: cup, offset: [0.05, -0.1, 0.1]}}}" in text
    assert "- {right: {fn: grasp, args: {obj: bottle}}}" in text


def test_yaml_syntax_error_has_line_and_column(tmp_path: Path) -> None:
    path = _write(tmp_path, "task: t\nstart: v0\nnodes: [\n  {id: v0\n")
    [line] = _problems(path)
    assert line.startswith(f"{path}: line 5, column 1: invalid YAML:")


def test_yaml_duplicate_key_is_an_error(tmp_path: Path) -> None:
    path = _write(tmp_path, "task: t\nstart: v0\ntask: u\n")
    assert _problems(path) == [
        f"{path}: line 3, column 1: invalid YAML: while constructing a mapping found duplicate key 'task'"
    ]


@pytest.mark.parametrize(
    ("text", "where", "key"),
    [
        ("a: {b: 1, b: 2}\n", "line 1, column 11", "'b'"),
        ("a: 1\n1.0: 2\n1: 3\n", "line 3, column 1", "1"),  # 1.0 and 1 are the same key
        ("base: &b {x: 1}\nd:\n  <<: *b\n  z: 3\n  z: 4\n", "line 5, column 3", "'z'"),  # beside a merge key
        ("- {id: v0}\n- {id: v1, id: v2}\n", "line 2, column 12", "'id'"),
    ],
)
def test_yaml_duplicate_keys_anywhere_are_errors(tmp_path: Path, text: str, where: str, key: str) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(GraphFileError) as info:
        read_document(path)
    assert info.value.problems == [
        f"{path}: {where}: invalid YAML: while constructing a mapping found duplicate key {key}"
    ]


@pytest.mark.parametrize(
    "text",
    [
        "a: &x [1, {b: 2}]\nc: *x\nd: &s word\ne: *s\n",
        "base: &b {x: 1, y: 2}\nd:\n  <<: *b\n  x: 3\n",
        "? '1'\n: quoted\n1: int\nnull: n\nfalse: f\n2.5: g\n",
        "t: 2001-12-14\nu: yes\nv: 1_000\nw: 0x1F\nx: !!str 12\ny: !!int '7'\nz: 0o17\n",
        "s: !!set {a, b}\no: !!omap [a: 1, b: 2]\nm: !!map {a: 1}\nq: !!seq [1]\nbin: !!binary aGVsbG8=\n",
        "text: |\n  block\n  lines\nflow: [a, 'b: c', \"d\", -1.5e3, ~]\n",
    ],
    ids=["aliases", "merge key", "keys of each kind", "YAML 1.1 scalars", "explicit tags", "styles"],
)
def test_yaml_documents_read_as_the_safe_loader_reads_them(tmp_path: Path, text: str) -> None:
    # The fast constructor (iterative, cached scalar tags) must build what PyYAML's own does.
    assert read_document(_write(tmp_path, text)) == yaml.safe_load(text)


def test_yaml_python_tags_are_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, "task: !!python/object/apply:os.system [echo hi]\n")
    [line] = _problems(path)
    assert "could not determine a constructor for the tag 'tag:yaml.org,2002:python/object/apply:os.system'" in line


@pytest.mark.parametrize("text", ["task: t\n", "task: [\n", "task: t\ntask: u\n"], ids=["ok", "syntax", "duplicate"])
def test_loading_resumes_the_garbage_collector(tmp_path: Path, text: str) -> None:
    # Loading pauses the cyclic collector (large graphs load 3x faster) and always resumes it.
    path = _write(tmp_path, text)
    assert gc.isenabled()
    with pytest.raises(GraphFileError):
        load_graph(path)
    assert gc.isenabled()
    gc.disable()
    try:
        with pytest.raises(GraphFileError):
            load_graph(path)
        assert not gc.isenabled()  # a caller's own pause is kept
    finally:
        gc.enable()


def test_json_syntax_error_and_duplicate_key(tmp_path: Path) -> None:
    path = _write(tmp_path, '{"task": "t",\n "start": }', "g.json")
    assert _problems(path) == [f"{path}: line 2, column 11: invalid JSON: Expecting value"]
    path = _write(tmp_path, '{"task": "t", "task": "u"}', "g.json")
    assert _problems(path) == [f"{path}: invalid JSON: duplicate key 'task'"]


def test_all_schema_errors_are_reported_with_field_paths(tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["edges"][1]["failures"][0]["window"] = 0
    data["edges"][1]["actions"]["right"]["fn"] = 3
    data["edges"][8]["actions"][1]["right"]["argz"] = {}
    del data["nodes"][2]["semantic"]
    data["edges"][0]["failure"] = []
    path = _write(tmp_path, yaml.safe_dump(data))
    assert sorted(_problems(path)) == sorted(
        [
            f"{path}: edges[1].failures[0].window: Input should be greater than or equal to 1",
            f"{path}: edges[1].actions.right.fn: Input should be a valid string",
            f"{path}: edges[8].actions[1].right.argz: Extra inputs are not permitted (did you mean 'args'?)",
            f"{path}: nodes[2].semantic: Field required",
            f"{path}: edges[0].failure: Extra inputs are not permitted (did you mean 'failures'?)",
        ]
    )


def test_single_step_list_keeps_its_index(tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["edges"][0]["actions"] = [{"right": {"fn": None}}]
    path = _write(tmp_path, json.dumps(data), "g.json")
    assert _problems(path) == [f"{path}: edges[0].actions[0].right.fn: Input should be a valid string"]


def test_unknown_field_without_close_match_lists_fields(tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["nodes"][0]["zzz"] = 1
    path = _write(tmp_path, yaml.safe_dump(data))
    assert _problems(path) == [
        f"{path}: nodes[0].zzz: Extra inputs are not permitted (fields: id, semantic, kind, constraints)"
    ]


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("", "expected a task graph (a mapping with task, start, goal, nodes, edges), found an empty file"),
        ("- a\n- b\n", "expected a task graph (a mapping with task, start, goal, nodes, edges), found a list"),
    ],
)
def test_top_level_must_be_a_mapping(tmp_path: Path, text: str, problem: str) -> None:
    path = _write(tmp_path, text)
    assert _problems(path) == [f"{path}: {problem}"]


def test_missing_file_and_unsupported_suffix(tmp_path: Path) -> None:
    missing = tmp_path / "nope.yaml"
    assert _problems(missing) == [f"{missing}: cannot read the file: No such file or directory"]
    toml = _write(tmp_path, "", "g.toml")
    assert _problems(toml) == [f"{toml}: unsupported file type '.toml'; use .yaml, .yml or .json"]
    with pytest.raises(GraphFileError, match=r"unsupported file type '\.txt'"):
        dump_graph(load_graph(POUR), tmp_path / "g.txt")


def test_error_text_is_all_lines(tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    del data["task"], data["goal"]
    path = _write(tmp_path, yaml.safe_dump(data))
    with pytest.raises(GraphFileError) as info:
        load_graph(path)
    assert str(info.value) == f"{path}: task: Field required\n{path}: goal: Field required"


def test_dump_leaves_defaults_out(tmp_path: Path) -> None:
    graph = TaskGraph.model_validate(
        {"task": "t", "start": "a", "goal": "a", "nodes": [{"id": "a", "semantic": "s"}], "edges": []}
    )
    data = yaml.safe_load(dump_graph(graph, tmp_path / "g.yaml").read_text())
    assert data == {"task": "t", "start": "a", "goal": "a", "nodes": [{"id": "a", "semantic": "s"}], "edges": []}
