"""Hostile and malformed inputs: each gets a clear error and its exit status, never a traceback.

Classes (issue "hardening"): 1 non-finite numbers, 2 object names, 3 graphs that check but
cannot run, 4 output paths, 5 LLM endpoints, 6 nesting, sizes and special files, 7 exit
statuses, 8 nonsense goals. Exit statuses: 0 ok, 1 task failed, 2 bad input, 3 internal error.
A watchdog fails any case that runs past 20 s (a hang), without timing assertions.
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from hostile_server import HostileServer, Reply, completion
from pydantic import ValidationError

from agentchord.cli import main
from agentchord.guard import (
    NonFiniteNumberError,
    NotARegularFileError,
    OutputPathError,
    TooDeepError,
    TooLargeError,
    atomic_write_text,
    check_finite,
    check_output_path,
    check_shape,
    finite_json,
    read_text,
)

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"
LLM_ENV = {"AGENTCHORD_LLM_MODEL": "hostile", "AGENTCHORD_LLM_API_KEY": "test"}


@pytest.fixture(autouse=True)
def watchdog():
    """Fail a case that hangs instead of waiting for it."""

    def expire(signum, frame):
        raise TimeoutError("a hostile input hung for 20 s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def invoke(args: list[str], code: int = 2, *needles: str, env: dict | None = None):
    """Run ``agentchord ARGS``; check the exit status, that no traceback escaped, and the message."""
    result = CliRunner().invoke(main, [str(a) for a in args], env=env)
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    for needle in needles:
        assert needle in result.output, result.output
    return result


def pour() -> dict:
    return yaml.safe_load(POUR.read_text())


def write(tmp_path: Path, data: dict | str, name: str = "g.yaml") -> Path:
    path = tmp_path / name
    if isinstance(data, str):
        path.write_text(data)
    elif name.endswith(".json"):
        path.write_text(json.dumps(data))  # NaN and Infinity written as JSON's non-standard literals
    else:
        path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def unwritable(tmp_path: Path, name: str) -> Path:
    """A path no one can create, root included: its folder is a regular file."""
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    return blocker / name


# --- 1. non-finite numbers -------------------------------------------------------------------

NUMBER_CASES = [
    ("offset nan", lambda d: d["edges"][1]["actions"]["right"]["args"].update(offset=[0.05, float("nan"), 0.1]),
     "edges[1].actions.right.args.offset[1]: NaN is not a number"),
    ("offset inf", lambda d: d["edges"][1]["actions"]["right"]["args"].update(offset=[float("inf"), 0, 0.1]),
     "edges[1].actions.right.args.offset[0]: infinity is not allowed"),
    ("offset huge", lambda d: d["edges"][1]["actions"]["right"]["args"].update(offset=[1e300, 0, 0.1]),
     "1e+300 is out of range"),
    ("pos nan", lambda d: d["edges"][0]["actions"].update(right={"fn": "move_to_target", "args": {"pos": [float("nan"), 0, 0.2]}}),
     "edges[0].actions.right.args.pos[0]: NaN"),
    ("place target -inf", lambda d: d["edges"][4]["actions"]["right"]["args"].update(target=[float("-inf"), 0.1]),
     "edges[4].actions.right.args.target[0]: -infinity"),
    ("rotate angle nan", lambda d: d["edges"][2]["actions"]["right"]["args"].update(angle=float("nan")),
     "edges[2].actions.right.args.angle: NaN"),
    ("margin nan", lambda d: d["edges"][1]["failures"][0].update(margin=float("nan")),
     "edges[1].failures[0].margin: NaN"),
    ("cost inf", lambda d: d["edges"][0].update(cost=float("inf")), "edges[0].cost: infinity"),
    ("monitor 0/0", lambda d: d["edges"][1]["failures"][0].update(monitor="0/0 + holding(right, bottle)"),
     "'0/0' is nan, not a finite number"),
    ("constraint 1e400", lambda d: d["nodes"][3].update(constraints=["1e400 - tilt(bottle)"]),
     "'1e400' is inf, not a finite number"),
    ("path constraint 1/0 in a vector", lambda d: d["edges"][1].update(path_constraints=["dist(bottle.pos, [0, 0, 1/0])"]),
     "'1/0' is inf"),
]


@pytest.mark.parametrize(("case", "change", "message"), NUMBER_CASES, ids=[c[0] for c in NUMBER_CASES])
def test_graph_check_refuses_non_finite_numbers(tmp_path, case, change, message):
    data = pour()
    change(data)
    invoke(["graph", "check", write(tmp_path, data)], 2, message)


def test_graph_check_refuses_nan_in_a_json_graph(tmp_path):
    data = pour()
    data["edges"][1]["actions"]["right"]["args"]["offset"] = [float("nan"), 0, 0]
    path = write(tmp_path, data, "g.json")
    assert "NaN" in path.read_text()
    invoke(["graph", "check", path], 2, f"{path}: edges[1].actions.right.args.offset[0]: NaN")


def test_run_refuses_a_nan_argument_before_the_episode(tmp_path):
    data = pour()
    data["edges"][1]["actions"]["right"]["args"]["offset"] = [float("nan"), 0, 0]
    invoke(["run", "single_arm_pour_water", "--graph", write(tmp_path, data)], 2, "NaN is not a number")


def test_filter_refuses_a_nan_graph_instead_of_writing_null(tmp_path):
    data = pour()
    data["edges"][1]["actions"]["right"]["args"]["offset"] = [float("nan"), 0, 0]
    out = tmp_path / "out.yaml"
    invoke(["graph", "filter", write(tmp_path, data), "-o", out], 2, "NaN")
    assert not out.exists()


@pytest.mark.parametrize("command", ["run", "demo"])
def test_p_nan_is_refused(command):
    args = [command, "single_arm_pour_water"] if command == "run" else [command]
    invoke([*args, "--p", "nan"], 2, "NaN is not a number")


@pytest.mark.parametrize(
    ("goal", "message"),
    [
        ({"kind": "placed", "obj": "red_block", "at": [float("nan"), 0.1]}, "goals[0].at[0]: NaN is not a number"),
        ({"kind": "placed", "obj": "red_block", "yaw": float("inf")}, "goals[0].yaw: infinity is not allowed"),
        ({"kind": "placed", "obj": "red_block", "relative_to": "cup", "offset": [1e9, 0]}, "goals[0].offset[0]: "),
        ({"kind": "placed", "obj": "red_block", "at": [900.0, 0.4]}, "goals[0].at[0]: Input should be less than or equal to 2"),
        ({"kind": "placed", "obj": "red_block", "yaw": 359}, "goals[0].yaw: Input should be less than or equal to 180"),
    ],
    ids=["at nan", "yaw inf", "offset huge", "at off the table", "yaw past 180"],
)
def test_a_goal_with_non_finite_numbers_is_refused(tmp_path, goal, message):
    path = write(tmp_path, {"goals": [goal]}, "goal.yaml")
    invoke(["plan", "--goal", path, "--task", "blocks_and_cup", "-o", tmp_path / "g.yaml"], 2, message)


def test_the_number_guard_names_the_path_and_accepts_numpy_and_large_ints():
    with pytest.raises(NonFiniteNumberError, match=r"a\.b\[1\]: NaN"):
        check_finite({"a": {"b": [1.0, np.float64("nan")]}})
    with pytest.raises(NonFiniteNumberError, match="out of range"):
        check_finite([10**400], max_abs=1e6)
    with pytest.raises(NonFiniteNumberError, match=r"\[0\]: 1e\+07 is out of range"):
        check_finite([10**7], max_abs=1e6)
    assert check_finite({"x": [1, 2.5, True, None, "nan"]}) == {"x": [1, 2.5, True, None, "nan"]}


def test_json_output_never_holds_nan():
    text = finite_json({"mean": float("nan"), "runs": [1.0, float("inf")]})
    assert json.loads(text) == {"mean": None, "runs": [1.0, None]}


def test_an_action_call_built_in_code_refuses_nan():
    from agentchord.graph.models import ActionCall

    with pytest.raises(ValidationError, match="offset\\[2\\]: NaN"):
        ActionCall(fn="move_to_obj", args={"obj": "cup", "offset": (0.0, 0.0, np.nan)})


# --- 2. object names -----------------------------------------------------------------------

NAME_CASES = [
    ("my bottle", "is not an identifier"),
    ("__import__", "cannot start or end with '__'"),
    ("right", "is the name of an arm"),
    ("dist", "is the name of a function"),
    ("lambda", "is a reserved word"),
    ("", "cannot be empty"),
    ("bottle\u00e9", "is not an identifier"),
]


@pytest.mark.parametrize(("name", "message"), NAME_CASES, ids=[repr(n) for n, _ in NAME_CASES])
def test_graph_check_refuses_object_names_that_expressions_cannot_use(tmp_path, name, message):
    data = pour()
    data["objects"] = ["bottle", name]
    invoke(["graph", "check", write(tmp_path, data)], 2, "objects[1]", message)


def test_run_refuses_a_bad_object_name(tmp_path):
    data = pour()
    data["objects"] = ["bottle", "my cup"]
    invoke(["run", "single_arm_pour_water", "--graph", write(tmp_path, data)], 2, "objects[1]: ")


def test_a_goal_with_a_bad_object_name_is_refused(tmp_path):
    path = write(tmp_path, {"goals": [{"kind": "inside", "obj": "my block", "container": "cup"}]}, "goal.yaml")
    invoke(["plan", "--goal", path, "--task", "blocks_and_cup", "-o", tmp_path / "g.yaml"], 2, "goals[0].obj: object name 'my block'")


def _release(tmp_path: Path, obj: str = "bottle") -> tuple[Path, Path]:
    graph = {
        "task": "pour water",
        "start": "s0",
        "goal": "s1",
        "nodes": [{"id": "s0", "semantic": "start"}, {"id": "s1", "semantic": "held"}],
        "edges": [{"id": "t1", "source": "s0", "target": "s1", "left_arm_action": None,
                   "right_arm_action": {"fn": "grasp", "kwargs": {"robot_name": "right_arm", "obj_name": obj}}}],
    }
    spec = {"task": "pour water", "recovery_bindings": []}
    return write(tmp_path, graph, "agent_task_graph.json"), write(tmp_path, spec, "agent_recovery_spec.json")


def test_import_release_refuses_an_object_name_that_is_not_an_identifier(tmp_path):
    graph, spec = _release(tmp_path, "my bottle")
    result = invoke(["import-release", graph, spec, "-o", tmp_path / "g.yaml"], 2, "is not an identifier")
    assert "--objects 'my bottle=NEW_NAME'" in result.output
    assert not (tmp_path / "g.yaml").exists()


def test_import_release_refuses_a_bad_rename(tmp_path):
    graph, spec = _release(tmp_path)
    invoke(["import-release", graph, spec, "-o", tmp_path / "g.yaml", "--objects", "bottle=__class__"], 2,
           "--objects: object name '__class__'")


def test_an_llm_reply_with_a_bad_object_name_is_a_problem_to_repair_not_a_crash():
    from agentchord.agents.llm import parse_reply
    from agentchord.agents.reasoner import ComposeRequest
    from agentchord.agents.scene import Scene, SceneObject

    scene = Scene(objects=[SceneObject(name="bottle", pos=(0, 0.4, 0.1), extent=(0.05, 0.05, 0.2))])
    reply = json.dumps({"task": "t", "start": "v0", "goal": "v1", "objects": ["my bottle"], "nodes": [], "edges": []})
    graph, problems = parse_reply(reply, ComposeRequest(instruction="x", scene=scene))
    assert graph is None and any(p.startswith("objects[0]: ") and "identifier" in p for p in problems)


# --- 3. graphs that check but cannot run ----------------------------------------------------


def test_a_graph_whose_goal_is_its_start_is_refused(tmp_path):
    data = pour()
    data["goal"] = data["start"]
    invoke(["graph", "check", write(tmp_path, data)], 2, "goal: the goal is the start node 'v0'")


def test_run_refuses_a_graph_for_another_scene(tmp_path):
    data = pour()
    text = yaml.safe_dump(data, sort_keys=False).replace("bottle", "jug")
    path = write(tmp_path, text)
    invoke(["graph", "check", path], 0)
    invoke(["run", "single_arm_pour_water", "--graph", path], 2,
           f"{path}: objects[0]: the single_arm_pour_water scene has no object 'jug' (it has bottle, cup)")


def test_graph_check_with_a_task_checks_the_scene(tmp_path):
    path = write(tmp_path, yaml.safe_dump(pour(), sort_keys=False).replace("bottle", "jug"))
    invoke(["graph", "check", path, "--task", "single_arm_pour_water"], 2,
           f"{path}: objects[0]: the single_arm_pour_water scene has no object 'jug'")
    invoke(["graph", "check", POUR, "--task", "single_arm_pour_water"], 0)
    invoke(["graph", "check", POUR, "--task", "nowhere"], 2, "unknown task 'nowhere'")


def test_run_refuses_a_towel_graph_on_the_blocks_scene():
    from agentchord.library import load_task_graph

    graph = load_task_graph("fold_towel")
    with pytest.raises(Exception) as caught:
        from agentchord.episode import EpisodeSpec, run_episode

        run_episode(EpisodeSpec(task="blocks_and_cup", graph=graph))
    assert type(caught.value).__name__ == "GraphNotRunnableError"
    assert "the blocks_and_cup scene has no object 'towel_bl'" in str(caught.value)


# --- 4. output paths -------------------------------------------------------------------------


@pytest.mark.parametrize("option", ["--json", "--trace", "--video"])
def test_run_checks_its_outputs_before_running(tmp_path, option):
    name = "e.mp4" if option == "--video" else "e.json"
    invoke(["run", "single_arm_pour_water", option, unwritable(tmp_path, name)], 2,
           f"cannot write {option} ", "cannot create its folder")


def test_run_video_needs_an_mp4_name(tmp_path):
    out = tmp_path / "episode.avi"
    invoke(["run", "single_arm_pour_water", "--video", out], 2, "unsupported file type '.avi'; use .mp4")
    assert not out.exists()


def test_demo_checks_its_json_before_any_trial(tmp_path):
    result = invoke(["demo", "--trials", "1", "--workers", "1", "--json", unwritable(tmp_path, "demo.json")], 2,
                    "cannot write --json")
    assert "episodes" not in result.output  # no trial ran


def test_an_output_that_is_a_directory_is_refused(tmp_path):
    invoke(["graph", "render", POUR, "-o", tmp_path], 2, "is a directory")
    folder = tmp_path / "figure.svg"
    folder.mkdir()
    invoke(["graph", "render", POUR, "-o", folder], 2, "is a directory")


@pytest.mark.parametrize(
    "args",
    [
        ["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", "{u}/g.yaml"],
        ["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", "{t}/g.txt"],
        ["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", "{t}/g.yaml", "--render", "{t}/g.jpg"],
        ["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", "{t}/g.yaml", "--trace", "{u}/t.jsonl"],
        ["graph", "filter", str(POUR), "-o", "{t}/g.txt"],
        ["graph", "render", str(POUR), "-o", "{u}/g.svg"],
    ],
    ids=["plan -o unwritable", "plan -o .txt", "plan --render .jpg", "plan --trace unwritable", "filter -o .txt",
         "render -o unwritable"],
)
def test_outputs_are_checked_before_the_work(tmp_path, args):
    blocked = unwritable(tmp_path, "x").parent
    result = invoke([a.format(t=tmp_path, u=blocked) for a in args], 2, "cannot write ")
    assert "composer" not in result.output  # refused before planning
    assert not (tmp_path / "g.yaml").exists()


def test_import_release_checks_its_output_first(tmp_path):
    graph, spec = _release(tmp_path)
    invoke(["import-release", graph, spec, "-o", tmp_path / "g.csv"], 2, "unsupported file type '.csv'")


def test_plan_creates_the_output_folders_and_renders_pdf(tmp_path):
    out, figure = tmp_path / "out" / "deeper" / "planned.yaml", tmp_path / "fig" / "planned.pdf"
    invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", out, "--render", figure], 0)
    assert out.exists() and figure.read_bytes().startswith(b"%PDF")


def test_a_failed_atomic_write_keeps_the_previous_file(tmp_path, monkeypatch):
    path = tmp_path / "result.json"
    path.write_text("previous")

    def refuse(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(OutputPathError, match="No space left on device"):
        atomic_write_text(path, "new")
    assert path.read_text() == "previous" and os.listdir(tmp_path) == ["result.json"]


def test_one_failing_output_does_not_lose_the_others(tmp_path):
    from rich.console import Console

    from agentchord.cli.episode import _write_outputs
    from agentchord.cli.support import BadInput

    good = tmp_path / "summary.json"

    def fail():
        raise OutputPathError("t.jsonl", "No space left on device")

    with pytest.raises(BadInput, match="cannot write trace t.jsonl"):
        _write_outputs(Console(file=open(os.devnull, "w")), [
            ("trace", "t.jsonl", fail),
            ("summary", str(good), lambda: atomic_write_text(good, "{}")),
        ])
    assert good.read_text() == "{}"


def test_writing_to_a_device_or_through_a_symlink_keeps_them(tmp_path):
    atomic_write_text("/dev/null", "discarded")
    assert Path("/dev/null").is_char_device()
    target = tmp_path / "real.json"
    link = tmp_path / "link.json"
    link.symlink_to(target)
    check_output_path(link)
    atomic_write_text(link, "{}")
    assert link.is_symlink() and target.read_text() == "{}"


def test_an_output_in_a_folder_that_takes_no_new_file_names_the_folder():
    # /proc exists, but no file can be created in it (the kernel answers ENOENT).
    with pytest.raises(OutputPathError, match=r"no file can be created in its folder '/proc' \(No such file or directory\)"):
        check_output_path("/proc/x.yaml", (".yaml",), "-o")


def test_check_output_path_leaves_nothing_behind(tmp_path):
    path = check_output_path(tmp_path / "new" / "x.json", (".json",), "--json")
    assert path.parent.is_dir() and os.listdir(path.parent) == []


# --- 5. LLM endpoints ----------------------------------------------------------------------

NAN_GRAPH = (
    '{"task": "blocks_and_cup", "start": "v0", "goal": "v1", "objects": ["red_block", "cup"], '
    '"nodes": [{"id": "v0", "semantic": "s"}, {"id": "v1", "semantic": "t"}], '
    '"edges": [{"id": "e1", "source": "v0", "target": "v1", '
    '"actions": {"right": {"fn": "move_to_target", "args": {"pos": [NaN, 0, 0.2]}}}}]}'
)


def _llm(server: HostileServer, **extra: str) -> dict:
    return {**LLM_ENV, "AGENTCHORD_LLM_BASE_URL": server.base_url, **extra}


def test_a_dripping_server_cannot_hold_a_plan_past_the_deadline(tmp_path):
    drip = Reply(completion(NAN_GRAPH), drip_s=0.1, chunk=2)
    # The reply alone would drip for over a minute; the watchdog fails the case if it is awaited.
    with HostileServer(lambda body: drip) as server:
        result = invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "--reasoner", "llm",
                         "-o", tmp_path / "g.yaml"], 2, "within the deadline of 1.5 s",
                        env=_llm(server, AGENTCHORD_LLM_TIMEOUT_S="0.5", AGENTCHORD_LLM_DEADLINE_S="1.5"))
    assert "timed out after 0.5 s" in result.output
    assert not (tmp_path / "g.yaml").exists()


def test_a_server_that_always_fails_is_given_up_at_the_deadline():
    from agentchord.agents.exceptions import ReasonerTransportError
    from agentchord.agents.llm import LlmConfig, LlmReasoner
    from agentchord.agents.reasoner import ComposeRequest
    from agentchord.agents.scene import Scene

    sleeps: list[float] = []
    with HostileServer(lambda body: Reply({"error": {"message": "busy"}}, status=503)) as server:
        config = LlmConfig(base_url=server.base_url, model="m", api_key="k", deadline_s=0.5, backoff_base_s=10,
                           max_retries=50)
        llm = LlmReasoner(config, sleep=lambda s: (sleeps.append(s), time.sleep(s)))
        with pytest.raises(ReasonerTransportError):
            llm.compose(ComposeRequest(instruction="x", scene=Scene(objects=[])))
    assert sum(sleeps) <= 0.5 + 1e-6


def test_an_llm_reply_with_nan_arguments_is_refused_and_its_trace_kept(tmp_path):
    trace = tmp_path / "calls.jsonl"
    with HostileServer(lambda body: Reply(completion(NAN_GRAPH))) as server:
        invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "--reasoner", "llm",
                "-o", tmp_path / "g.yaml", "--trace", trace], 2,
               "edges[0].actions.right.args.pos[0]: NaN is not a number", str(trace), env=_llm(server))
        assert len(server.requests) == 4  # the first answer and 3 repairs
    assert not (tmp_path / "g.yaml").exists()
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    assert events[0]["event"] == "reasoner_call" and not events[0]["ok"]
    assert len(events[0]["attempts"]) == 4 and "NaN" in events[0]["attempts"][0]["reply"]


@pytest.mark.parametrize(
    ("content", "usage", "message"),
    [
        ([{"type": "text", "text": "{}"}], None, "the reply's content is a JSON array; expected a string"),
        ({"graph": {}}, None, "the reply's content is a JSON object; expected a string"),
        (NAN_GRAPH, {"prompt_tokens": "many", "completion_tokens": [1]}, "NaN is not a number"),
        ("[" * 100_000 + "]" * 100_000, None, "nested too deeply"),
    ],
    ids=["content list", "content object", "usage not numeric", "nested reply"],
)
def test_malformed_llm_replies_are_problems_not_crashes(content, usage, message):
    from agentchord.agents.exceptions import InvalidReplyError
    from agentchord.agents.llm import LlmConfig, LlmReasoner
    from agentchord.agents.reasoner import ComposeRequest
    from agentchord.agents.scene import Scene

    with HostileServer(lambda body: Reply(completion(content, usage))) as server:
        llm = LlmReasoner(LlmConfig(base_url=server.base_url, model="m", api_key="k", max_repairs=1))
        with pytest.raises(InvalidReplyError) as caught:
            llm.compose(ComposeRequest(instruction="x", scene=Scene(objects=[])))
    assert any(message in problem for problem in caught.value.problems), caught.value.problems
    call = llm.calls[0]
    assert call.tokens_in == 0 and call.tokens_out == 0 or usage is None


def test_an_oversized_reply_is_refused_and_not_sent_back():
    from agentchord.agents.exceptions import InvalidReplyError
    from agentchord.agents.llm import LlmConfig, LlmReasoner
    from agentchord.agents.reasoner import ComposeRequest
    from agentchord.agents.scene import Scene

    huge = "{" + " " * 3_000_000 + "}"
    with HostileServer(lambda body: Reply(completion(huge))) as server:
        llm = LlmReasoner(LlmConfig(base_url=server.base_url, model="m", api_key="k", max_repairs=1,
                                    max_reply_chars=100_000))
        with pytest.raises(InvalidReplyError, match="no valid task graph"):
            llm.compose(ComposeRequest(instruction="x", scene=Scene(objects=[])))
        repair_request = server.requests[1]
    assert "more than the limit of 100,000" in llm.calls[0].attempts[0].problems[0]
    assert len(json.dumps(repair_request)) < 100_000


@pytest.mark.parametrize(
    ("variable", "value"),
    [("AGENTCHORD_LLM_TIMEOUT_S", "nan"), ("AGENTCHORD_LLM_DEADLINE_S", "inf"), ("AGENTCHORD_LLM_MAX_REPLY_CHARS", "-1"),
     ("AGENTCHORD_LLM_TEMPERATURE", "nan")],
)
def test_bad_llm_settings_are_bad_input(tmp_path, variable, value):
    env = {**LLM_ENV, "AGENTCHORD_LLM_BASE_URL": "http://127.0.0.1:9/v1", variable: value}
    invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "--reasoner", "llm",
            "-o", tmp_path / "g.yaml"], 2, "invalid LLM reasoner settings", env=env)


# --- 6. nesting, sizes and special files -------------------------------------------------------


def _deep(levels: int) -> str:
    return "[" * levels + "]" * levels


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
@pytest.mark.parametrize("levels", [40, 20_000])
def test_a_deeply_nested_graph_is_refused(tmp_path, suffix, levels):
    text = f'{{"task": "t", "start": "v0", "goal": "v1", "nodes": {_deep(levels)}, "edges": []}}'
    path = write(tmp_path, text, f"g{suffix}")
    invoke(["graph", "check", path], 2, str(path), "nest")


def test_a_deeply_nested_goal_spec_is_refused(tmp_path):
    path = write(tmp_path, '{"goals": ' + _deep(5000) + "}", "goal.json")
    invoke(["plan", "--goal", path, "--task", "blocks_and_cup", "-o", tmp_path / "g.yaml"], 2, "nested")


def test_a_deeply_nested_release_file_is_refused(tmp_path):
    graph, spec = _release(tmp_path)
    spec.write_text('{"nodes": ' + _deep(50_000) + "}")
    invoke(["import-release", graph, spec, "-o", tmp_path / "g.yaml"], 2, "nested too deeply")


def test_a_yaml_alias_bomb_is_refused(tmp_path, monkeypatch):
    import agentchord.guard.documents as documents

    monkeypatch.setattr(documents, "MAX_VALUES", 100_000)
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]"
              for i in range(1, 9)]
    path = write(tmp_path, "\n".join(lines) + "\ntask: t\n")
    invoke(["graph", "check", path], 2, "more than 100,000 values")


def test_a_fifo_given_as_a_graph_does_not_hang(tmp_path):
    fifo = tmp_path / "g.yaml"
    os.mkfifo(fifo)
    invoke(["graph", "check", fifo], 2, "not a regular file")


def test_dev_zero_given_as_a_graph_is_refused(tmp_path):
    link = tmp_path / "zero.yaml"
    link.symlink_to("/dev/zero")
    invoke(["graph", "check", link], 2, "not a regular file")
    invoke(["graph", "render", link, "-o", tmp_path / "g.dot"], 2, "not a regular file")


def test_a_folder_given_as_a_graph_is_refused(tmp_path):
    folder = tmp_path / "g.yaml"
    folder.mkdir()
    invoke(["graph", "check", folder], 2, "a directory")


def test_a_file_over_the_size_limit_is_refused(tmp_path, monkeypatch):
    import agentchord.guard.documents as documents

    monkeypatch.setattr(documents, "MAX_FILE_BYTES", 1000)
    invoke(["graph", "check", POUR], 2, "the limit is 1,000 bytes")


@pytest.mark.parametrize(
    ("content", "message"),
    [(b"\xff\xfe task: t", "cannot read the file"), (b"", "found an empty file"), (b"- a\n- b\n", "found a list"),
     (b"task: [\n", "invalid YAML")],
    ids=["not utf-8", "empty", "a list", "broken yaml"],
)
def test_malformed_graph_files(tmp_path, content, message):
    path = tmp_path / "g.yaml"
    path.write_bytes(content)
    invoke(["graph", "check", path], 2, message)


def test_the_document_guards_directly(tmp_path):
    with pytest.raises(TooDeepError) as caught:
        check_shape({"a": [[[1]]]}, max_depth=3)
    assert caught.value.where == "a[0][0]"
    shared = [1] * 10
    with pytest.raises(TooLargeError):
        check_shape([shared] * 10, max_values=50)  # shared values count once per reference
    with pytest.raises(NotARegularFileError):
        read_text(tmp_path)


# --- 7. exit statuses ------------------------------------------------------------------------


def test_an_unexpected_error_is_one_line_and_a_log(tmp_path, monkeypatch):
    import agentchord.cli.graph as graph_cli

    def broken(graph):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(graph_cli, "check_graph", broken)
    result = invoke(["graph", "check", POUR], 3, "internal error: ZeroDivisionError: a bug (details in ",
                    env={"AGENTCHORD_LOG_DIR": str(tmp_path / "logs")})
    assert len(result.output.strip().splitlines()) == 1
    (log,) = (tmp_path / "logs").iterdir()
    assert "Traceback" in log.read_text() and "ZeroDivisionError: a bug" in log.read_text()


def test_an_interrupt_is_not_a_task_failure(monkeypatch):
    import agentchord.cli.graph as graph_cli

    def interrupted(graph):
        raise KeyboardInterrupt

    monkeypatch.setattr(graph_cli, "check_graph", interrupted)
    invoke(["graph", "check", POUR], 130, "agentchord: interrupted")


@pytest.mark.parametrize("command", [["graph", "check"], ["graph", "render"], ["graph", "filter"]])
def test_an_unreadable_file_is_exit_2(tmp_path, command):
    extra = ["-o", tmp_path / "g.dot"] if command[-1] == "render" else []
    invoke([*command, tmp_path / "missing.yaml", *extra], 2, "cannot read the file")


def test_an_unknown_task_is_exit_2():
    invoke(["run", "no_such_task"], 2, "unknown task")


@pytest.mark.parametrize(
    "args",
    [["run", "single_arm_pour_water", "--seed", "-1"],
     ["plan", "x", "--task", "blocks_and_cup", "-o", "never.yaml", "--seed", "-5"],
     ["demo", "--seed", "-3"]],
    ids=["run", "plan", "demo"],
)
def test_a_negative_seed_is_exit_2(args):
    invoke(args, 2, "'--seed'")


def test_an_unknown_camera_is_refused_before_the_episode(tmp_path):
    invoke(["run", "single_arm_pour_water", "--video", tmp_path / "v.mp4", "--camera", "nosuch"], 2,
           "no camera 'nosuch' in the single_arm_pour_water scene (cameras: front")
    assert not (tmp_path / "v.mp4").exists()


# --- 8. nonsense goals -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("task", "instruction", "message"),
    [
        ("blocks_and_cup", "put the cup into the red block", "'red_block' is not a container"),
        ("setup_coffee_tray", "put the tray into the capsule", "'capsule' is not a container"),
        ("blocks_and_cup", "stack the red block on the blue block and stack the blue block on the red block",
         "a cycle: red_block on top of blue_block on top of red_block"),
    ],
    ids=["cup into block", "tray into capsule", "stack cycle"],
)
def test_nonsense_instructions_are_refused_with_the_reason(tmp_path, task, instruction, message):
    invoke(["plan", instruction, "--task", task, "-o", tmp_path / "g.yaml"], 2, "the goal cannot be achieved", message)
    assert not (tmp_path / "g.yaml").exists()


@pytest.mark.parametrize(
    ("goals", "message"),
    [
        ([{"kind": "on_top_of", "obj": "red_block", "support": "blue_block"},
          {"kind": "on_top_of", "obj": "blue_block", "support": "red_block"}], "a cycle"),
        ([{"kind": "inside", "obj": "cup", "container": "cup"}], "'cup' cannot be inside itself"),
        ([{"kind": "inside", "obj": "red_block", "container": "blue_block"}], "'blue_block' is not a container"),
        ([{"kind": "inside", "obj": "red_block", "container": "mug"}], "the scene has no 'mug'"),
        ([{"kind": "placed", "obj": "red_block", "region": "nowhere"}], "the scene has no region 'nowhere'"),
        ([{"kind": "poured", "source": "red_block", "target": "cup"}], "'red_block' is not a vessel to pour from"),
        ([{"kind": "handed_over", "obj": "cup", "giver": "left", "receiver": "left"}], "cannot hand 'cup' over to itself"),
        ([{"kind": "placed", "obj": "red_block", "at": [0.1, 0.4], "relative_to": "cup"}], "one way only"),
        ([{"kind": "on_top_of", "obj": "red_block", "support": "cup"}], "fits through the opening of 'cup'"),
        ([{"kind": "placed", "obj": "red_block", "at": [0.0, 1.5]}], "is beyond both arms' reach for 'red_block'"),
    ],
    ids=["cycle", "inside itself", "into a block", "unknown object", "unknown region", "pour from a block",
         "hand over to itself", "two places at once", "on a cup it falls into", "beyond reach"],
)
def test_nonsense_goal_specs_are_refused(tmp_path, goals, message):
    path = write(tmp_path, {"goals": goals}, "goal.yaml")
    invoke(["plan", "--goal", path, "--task", "blocks_and_cup", "-o", tmp_path / "g.yaml"], 2, message)


def test_an_object_too_big_for_its_container_is_refused():
    from agentchord.agents.scene import Scene, SceneObject
    from agentchord.agents.rules.feasibility import goal_problems
    from agentchord.agents.rules.goals import GoalSpec

    scene = Scene(objects=[
        SceneObject(name="box", pos=(0, 0.4, 0.05), extent=(0.12, 0.12, 0.1)),
        SceneObject(name="cup", pos=(0.1, 0.4, 0.05), extent=(0.08, 0.08, 0.1)),
    ])
    goal = GoalSpec(goals=[{"kind": "inside", "obj": "box", "container": "cup"}])
    (problem,) = goal_problems(goal, scene)
    assert "'box' (12.0 cm across) does not fit into 'cup'" in problem
    assert goal_problems(GoalSpec(goals=[{"kind": "inside", "obj": "cup", "container": "box"}]), scene) == []


def test_an_object_nearly_as_wide_as_a_cup_does_not_fit_through_its_walls():
    """The walls take a share of the outer size perception sees: a 4.9 cm bottle does not go into a 5.2 cm cup."""
    from agentchord.agents.scene import Scene, SceneObject
    from agentchord.agents.rules.feasibility import goal_problems
    from agentchord.agents.rules.goals import GoalSpec

    scene = Scene(objects=[
        SceneObject(name="bottle", pos=(0, 0.4, 0.08), extent=(0.049, 0.049, 0.17)),
        SceneObject(name="cup", pos=(0.1, 0.4, 0.05), extent=(0.052, 0.052, 0.1)),
        SceneObject(name="block", pos=(-0.1, 0.4, 0.02), extent=(0.03, 0.03, 0.03)),
    ])
    (problem,) = goal_problems(GoalSpec(goals=[{"kind": "inside", "obj": "bottle", "container": "cup"}]), scene)
    assert "'bottle' (4.9 cm across) does not fit into 'cup'" in problem
    assert goal_problems(GoalSpec(goals=[{"kind": "inside", "obj": "block", "container": "cup"}]), scene) == []


@pytest.mark.parametrize("content", ['{"task": "blocks_and_cup", "nodes": [{"id": "v\\ud800"}]}',
                                     '{"task": "blocks_and_cup", "nodes": [{"id": "v\ud800"}]}'],
                         ids=["escaped in the reply's JSON", "raw in the content"])
def test_a_reply_holding_a_lone_surrogate_is_refused_and_its_trace_kept(tmp_path, content):
    """Issue 58: a composer reply holding ``"\\ud800"`` made ``plan`` exit 3 (UnicodeEncodeError) with no trace."""
    trace = tmp_path / "calls.jsonl"
    with HostileServer(lambda body: Reply(completion(content))) as server:
        invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "--reasoner", "llm",
                "-o", tmp_path / "g.yaml", "--trace", trace], 2, "lone surrogate", str(trace), env=_llm(server))
    assert not (tmp_path / "g.yaml").exists()
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    assert events[0]["event"] == "reasoner_call" and not events[0]["ok"]


@pytest.mark.parametrize("body", [b'{"choices": [ {"mess', b'{"choices": [], "x": "\xff"}', b"[" * 100_000 + b"]" * 100_000],
                         ids=["cut short", "not UTF-8", "nested past the parser"])
def test_an_unreadable_response_body_is_retried_then_a_transport_error_with_the_trace_kept(tmp_path, body):
    """Issue 58 (an adversarial pass): an HTTP 200 whose body the client cannot read was an internal error
    (exit 3: JSONDecodeError, UnicodeDecodeError, RecursionError) with no trace written."""
    trace = tmp_path / "calls.jsonl"
    with HostileServer(lambda request: Reply(body)) as server:
        invoke(["plan", "put the red block into the cup", "--task", "blocks_and_cup", "--reasoner", "llm",
                "-o", tmp_path / "g.yaml", "--trace", trace], 2, "an unreadable response body",
               env=_llm(server, AGENTCHORD_LLM_DEADLINE_S="2"))
    assert trace.exists() and not (tmp_path / "g.yaml").exists()


LONG = "a" * 300


@pytest.mark.parametrize("args", [
    ["run", "single_arm_pour_water", "--json", "{t}/" + LONG + ".json"],
    ["plan", "pour water from the bottle into the cup", "--task", "single_arm_pour_water", "-o", "{t}/" + LONG + ".json"],
    ["bench", "--tasks", "single_arm_pour_water", "--methods", "agentchord", "--trials", "1", "--p", "0", "--out", "{t}/" + LONG],
    ["record", "single_arm_pour_water", "--episodes", "1", "--camera", "none", "--out", "{t}/" + LONG],
    ["bench", "--tasks", "single_arm_pour_water", "--methods", "agentchord", "--trials", "1", "--p", "0", "--out", ""],
], ids=["run --json", "plan -o", "bench --out", "record --out", "bench --out ''"])
def test_an_output_name_no_file_system_takes_is_refused_before_the_work(tmp_path, args):
    """An adversarial pass (issue 58): a name over 255 bytes was an internal error (exit 3) after the work, and
    `bench --out ''` wrote its sweep into the current folder."""
    invoke([a.replace("{t}", str(tmp_path)) for a in args], 2, "--out" if "bench" in args or "record" in args else "bytes long")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("goal_text", "message"), [
    ("goal:\n  - {kind: inside, obj: red_block, container: cup}\n", "goal: Extra inputs are not permitted (did you mean 'goals'?)"),
    ("goals:\n  - {kind: inside, obj: red_block, contianer: cup}\n",
     "goals[0].contianer: Extra inputs are not permitted (did you mean 'container'?)"),
], ids=["goal for goals", "a kind's field"])
def test_a_goal_files_typo_is_answered_with_the_field_it_meant(tmp_path, goal_text, message):
    """It suggested the graph's fields ('goal' for 'goal'), the goal file being read with the graph's hints."""
    path = tmp_path / "goal.yaml"
    path.write_text(goal_text)
    invoke(["plan", "--goal", path, "--task", "blocks_and_cup", "-o", tmp_path / "g.yaml"], 2, message)
