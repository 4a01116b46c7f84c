"""The prompt evaluation: each case's replies replayed through ``plan --reasoner llm``, checked against
the requests they answer; what the model is sent (the whole scene, the skill notes a task needs)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner
from replay_server import Completion, HttpError, ReplayServer

from agentchord.agents import ArrangeRequest, ComposeRequest, ConductRequest, Scene, SceneObject
from agentchord.agents.llm import request_message, scene_json, system_prompt
from agentchord.agents.llm.fixtures import (
    FixtureBook,
    FixtureError,
    FixtureMissing,
    FixtureOutdated,
    message_agent,
    request_digest,
)
from agentchord.agents.llm.sizes import estimate_tokens, prompt_size
from agentchord.agents.llm.skills import SkillNotesError, graph_features, parse_skill_notes, select_notes, skill_notes
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules.goals import GoalSpec
from agentchord.agents.rules.instructions import ground_instruction
from agentchord.agents.scene import ArmState, Region
from agentchord.cli import main
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.graph.loader import load_graph
from agentchord.graph.models import TaskGraph
from agentchord.library import load_task_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world

CASES_DIR = Path(__file__).parent / "data" / "llm"
CASES = sorted(p.name for p in CASES_DIR.iterdir() if (p / "case.yaml").is_file())


def scene_with_regions() -> Scene:
    return Scene(
        objects=[SceneObject(name="block", description="orange block", pos=(-0.18, 0.53, 0.09), extent=(0.04, 0.04, 0.19))],
        arms=[ArmState(name="left", ee=(-0.2, 0.5, 0.3)), ArmState(name="right", ee=(0.2, 0.5, 0.3))],
        regions=[Region(name="target", description="target region on the right half", center=(0.12, 0.45), radius=0.04)],
        notes="table top at z = 0",
    )


def fixture_responder(book: FixtureBook):
    """Answer each chat request with the case's stored reply; refuse (HTTP 418, not retried) otherwise."""

    def respond(body) -> Completion | HttpError:
        try:
            return Completion(book.answer(body["messages"]))
        except FixtureError as error:
            return HttpError(418, str(error))

    return respond


# --- what the model is sent ------------------------------------------------------------------


def test_every_agent_request_holds_the_facts_the_rules_reasoner_reads():
    # The rules reasoner reads the Scene object; the model reads scene_json in its user message.
    scene = scene_with_regions()
    block = scene_json(scene)
    assert Scene.model_validate(json.loads(block)) == scene  # every field, nothing dropped
    message = request_message(ComposeRequest(instruction="Hand the block over.", scene=scene))
    assert block in message
    assert '"center": [0.12, 0.45]' in message and "table top at z = 0" in message


@pytest.mark.parametrize(("case", "words"), [
    ("handover_block", '{"name": "target", "description": "target region on the right half of the table", "center": [0.12, 0.45], "radius": 0.04}'),
    ("setup_coffee_tray", '{"name": "forward", "description": "forward front position where the tray goes", "center": [0.0, 0.67], "radius": 0.03}'),
])
def test_task_regions_reach_every_agent(case, words):
    for request in sorted((CASES_DIR / case).glob("*.request.md")):
        assert words in request.read_text(encoding="utf-8"), request.name


def test_skill_notes_follow_the_request():
    def notes(instruction: str, scene: Scene) -> set[str]:
        return {note.name for note in select_notes(ComposeRequest(instruction=instruction, scene=scene))}

    scene = scene_with_regions()
    assert notes("Hand the block over to the right arm.", scene) == {"handover", "regions"}  # region named in the scene
    pour = Scene(objects=[SceneObject(name="bottle", pos=(0.1, 0.4, 0.09), extent=(0.05, 0.05, 0.18))])
    assert notes("Pour water from the bottle.", pour) == {"pouring"}
    towel = Scene(objects=[SceneObject(name="towel_bl", pos=(0.0, 0.4, 0.0), extent=(0.01, 0.01, 0.01))])
    assert "cloth" in notes("Fold it in half.", towel)
    prompt = system_prompt("arranger", request=ComposeRequest(instruction="Hand the block over.", scene=scene))
    assert "Recovering a hand-over" in prompt  # the arranger's paragraph
    assert "Recovering a hand-over" not in system_prompt("composer", request=ComposeRequest(instruction="Hand the block over.", scene=scene))
    assert "# Skill notes" not in system_prompt("composer")


def _handover_graph(giver: str, receiver: str) -> TaskGraph:
    """A nominal hand-over of the block from ``giver`` to ``receiver``, then a place."""
    def step(arm: str, fn: str, **args) -> dict:
        return {arm: {"fn": fn, "args": args}}
    edges = [
        step(giver, "grasp", obj="block", mode="side", height=0.85),
        step(giver, "move_to_target", pos=[0.0, 0.5, 0.25]),
        step(receiver, "grasp", obj="block", mode="side", height=0.2, lift=0.0),
        step(giver, "open_gripper"),
        step(receiver, "place", obj="block", target=[0.0, 0.45]),
    ]
    return TaskGraph.model_validate({
        "task": "t", "start": "v0", "goal": f"v{len(edges)}", "objects": ["block"],
        "nodes": [{"id": f"v{i}", "semantic": f"s{i}"} for i in range(len(edges) + 1)],
        "edges": [{"id": f"e{i + 1}", "source": f"v{i}", "target": f"v{i + 1}", "actions": a} for i, a in enumerate(edges)],
    })


def test_arranger_and_conductor_notes_follow_what_the_graph_does():
    scene = Scene(objects=[SceneObject(name="block", pos=(0.1, 0.5, 0.1), extent=(0.04, 0.04, 0.2))])
    for giver, receiver in (("left", "right"), ("right", "left")):
        graph = _handover_graph(giver, receiver)
        assert graph_features(graph, scene) == {"handover"}
        assert {n.name for n in select_notes(ArrangeRequest(graph=graph, scene=scene))} == {"handover"}
    # The words of the instruction do not choose the arranger's notes: the graph does.
    graph = _handover_graph("right", "left").model_copy(update={"instruction": "Pour the block beside the tray."})
    assert {n.name for n in select_notes(ConductRequest(graph=graph, scene=scene))} == {"handover"}
    # The note is written for either giver.
    text = next(n for n in skill_notes() if n.name == "handover").text("arranger")
    assert "holding(left" not in text and "right.closed" not in text


def test_every_note_is_selectable_and_malformed_notes_are_named():
    assert {note.name for note in skill_notes()} >= {"handover", "two_arm_carry", "cloth", "placement", "thin_flat", "inside", "pouring", "regions"}
    assert all(note.when and note.does for note in skill_notes())
    with pytest.raises(SkillNotesError, match="unknown Does: juggling"):
        parse_skill_notes("## x\nWhen: y\nDoes: juggling\nTitle: X\n\ntext\n")
    with pytest.raises(SkillNotesError, match="section 'x': expected a When: line"):
        parse_skill_notes("## x\nTitle: X\n\ntext\n")
    with pytest.raises(SkillNotesError, match=r"unknown agent tag \[planner\]"):
        parse_skill_notes("## x\nWhen: y\nTitle: X\n\n[planner] text\n")


def test_prompt_size_counts_the_notes():
    request = ComposeRequest(instruction="Hand the block over.", scene=scene_with_regions())
    size = prompt_size(request)
    assert size.agent == "composer" and size.notes_chars > 0
    assert size.system_chars == len(system_prompt("composer", request=request))
    assert size.tokens == estimate_tokens("x" * size.chars)


# --- the replay fixtures --------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES)
def test_fixtures_answer_their_requests_and_plan(case, tmp_path, monkeypatch):
    """``plan --reasoner llm`` against the case's replies: every request must be the one answered."""
    book = FixtureBook.load(CASES_DIR / case)
    args = ["plan", book.case.instruction, "--task", book.case.task, "--seed", str(book.case.seed), "--reasoner", "llm", "-o", str(tmp_path / "g.yaml")]
    if book.case.goal is not None:
        goal = tmp_path / "goal.yaml"
        goal.write_text(yaml.safe_dump(book.case.goal))
        args += ["--goal", str(goal)]
    with ReplayServer(fixture_responder(book)) as server:
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "fixture")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "none")
        result = CliRunner().invoke(main, args)
    assert not book.problems, "fixtures to answer again:\n" + "\n".join(book.problems)
    assert result.exit_code == 0, result.output
    assert book.answered == len(book.case.turns)  # every stored reply used, in order
    graph = load_graph(tmp_path / "g.yaml")
    assert graph.recovery_edges(), "the arranger's recovery branches survived the plan"


def test_a_changed_request_is_flagged_not_answered(tmp_path):
    folder = tmp_path / "case"
    shutil.copytree(CASES_DIR / "handover_block", folder)
    book = FixtureBook.load(folder)
    first = (folder / "01-composer.request.md").read_text(encoding="utf-8")
    system = first.split("<!-- message 1: user -->")[0]
    messages = [{"role": "system", "content": "You are ... (the composer) of AgentChord" + system}, {"role": "user", "content": "changed"}]
    with pytest.raises(FixtureOutdated, match="01-composer.reply.json: answers another request"):
        book.answer(messages)
    recording = FixtureBook.load(folder, record=True)
    with pytest.raises(FixtureOutdated):
        recording.answer(messages)
    assert (folder / "01-composer.reply.stale.json").is_file() and not (folder / "01-composer.reply.json").exists()
    assert FixtureBook.load(folder).case.turns[0].request_sha256 == request_digest(messages)
    with pytest.raises(FixtureMissing, match="no reply to turn 1"):
        FixtureBook.load(folder).answer(messages)


def test_fixture_errors_name_the_file(tmp_path):
    with pytest.raises(FixtureError, match="case.yaml: no such case file"):
        FixtureBook.load(tmp_path)
    (tmp_path / "case.yaml").write_text("task: t\n")
    with pytest.raises(FixtureError, match="case.yaml: not a fixture case"):
        FixtureBook.load(tmp_path)
    with pytest.raises(FixtureError, match="not the system prompt"):
        message_agent([{"role": "user", "content": "hi"}])


# --- the episodes (slow) --------------------------------------------------------------------


#: Cases whose planned graph does not yet meet 3 of 3 undisturbed (docs/llm.md says why).
SHORT: dict[str, str] = {}  # case -> why its graph is known to fall short (an xfail reason); none at present


@pytest.mark.slow
@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.xfail(reason=SHORT[c], strict=False)) if c in SHORT else c for c in CASES])
def test_planned_graph_succeeds_undisturbed(case):
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1] / "benchmarks"))
    from llm_prompt_eval import plan_case, run_episodes

    graph, _ = plan_case(case)
    rows = run_episodes(FixtureBook.load(CASES_DIR / case).case.task, graph, [0, 1, 2], None)
    assert all(row["success"] for row in rows), rows


# --- the goal each composer reply states -----------------------------------------------------


def _agrees(a: dict, b: dict) -> bool:
    """Whether two goal predicates ask for the same thing: kind, objects, roles and region equal, places
    within 4 cm, yaws within 20 degrees (a long axis either way); an arm or a yaw that one of them
    leaves open (the instruction names none) matches any."""
    for key in a.keys() | b.keys():
        x, y = a.get(key), b.get(key)
        if key in ("arm", "yaw") and (x is None or y is None):
            continue
        if key in ("at", "offset"):
            x, y = x or (0.0, 0.0), y or (0.0, 0.0)
            if max(abs(float(p) - float(q)) for p, q in zip(x, y)) > 0.04:
                return False
        elif key == "yaw":
            if abs((float(x) - float(y) + 90) % 180 - 90) > 20:
                return False
        elif key == "hold_target":
            continue  # how the pour is steadied, not what it achieves
        elif x != y:
            return False
    return True


def _same_goal(a: GoalSpec, b: GoalSpec) -> bool:
    left = [g.model_dump(mode="json") for g in a.goals]
    right = [g.model_dump(mode="json") for g in b.goals]
    if len(left) != len(right):
        return False
    unmatched = list(right)
    for item in left:
        match = next((other for other in unmatched if _agrees(item, other)), None)
        if match is None:
            return False
        unmatched.remove(match)
    return True


#: Cases whose instruction leaves the end open, read two ways: the offline reasoner puts what is left in
#: a hand back where it was taken from (the arms end empty); the model keeps it held. Their goals must
#: differ by exactly that trailing put-back.
LEFT_IN_HAND = {"gym_transfer_cube": "the left hand keeps the cube (\"hand it to the left arm\" says no more)"}


@pytest.mark.parametrize("case", CASES)
def test_each_composer_states_the_goal_the_offline_reasoner_reads(case):
    """The goal a reply states (``success.goal_spec``) is the one the rules reasoner reads in the same
    instruction and scene: the episode is judged the same whichever reasoner planned it."""
    book = FixtureBook.load(CASES_DIR / case)
    reply = json.loads((CASES_DIR / case / "01-composer.reply.json").read_text(encoding="utf-8"))
    stated = GoalSpec.model_validate(reply["success"]["goal_spec"])
    scene = observe(open_world(book.case.task, book.case.seed), task_regions(SIM_TASKS[book.case.task]))
    offline = ground_instruction(book.case.instruction, scene)
    if case in LEFT_IN_HAND:
        put_back = offline.goals[-1]
        assert put_back.kind == "placed" and put_back.region is None and put_back.at is None and put_back.relative_to is None
        offline = offline.model_copy(update={"goals": offline.goals[:-1]})
    assert _same_goal(stated, offline), (stated.model_dump(mode="json", exclude_defaults=True), offline.model_dump(mode="json", exclude_defaults=True))


def test_an_llm_plan_is_judged_by_the_goal_its_composer_stated(tmp_path, monkeypatch):
    """A hand-over the other way round than the scene's own task: done as asked it is a SUCCESS (not
    the task's check, which wants the left arm to give); done the task's way, it is a FAILURE."""
    book = FixtureBook.load(CASES_DIR / "handover_reversed")
    with ReplayServer(fixture_responder(book)) as server:
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "fixture")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "none")
        planned = CliRunner().invoke(main, ["plan", book.case.instruction, "--task", "handover_block", "--reasoner", "llm",
                                            "-o", str(tmp_path / "g.yaml")])
    assert planned.exit_code == 0, planned.output
    assert "judged by this graph's own goal" in planned.output
    graph = load_graph(tmp_path / "g.yaml")
    goal = GoalSpec.model_validate(graph.success.goal_spec)
    assert graph.success.judge == "goal" and (goal.goals[0].giver, goal.goals[0].receiver) == ("right", "left")

    done_right = run_episode(EpisodeSpec(task="handover_block", seed=0, graph=graph))
    assert done_right.success, done_right.reason
    the_tasks_way = load_task_graph("handover_block").model_copy(update={"success": graph.success})
    done_wrong = run_episode(EpisodeSpec(task="handover_block", seed=0, graph=the_tasks_way))
    assert not done_wrong.success and "handed over" in done_wrong.reason, done_wrong.reason
    # The task's own check would have called the wrong one a success.
    assert run_episode(EpisodeSpec(task="handover_block", seed=0)).success


def test_run_with_an_llm_instruction_is_judged_by_the_stated_goal(monkeypatch):
    """`run --instruction --reasoner llm` (the robot moves on the composed graph, the arranger and the
    conductor answer while it moves) judges the episode by the goal the composer stated."""
    book = FixtureBook.load(CASES_DIR / "handover_reversed")
    with ReplayServer(fixture_responder(book)) as server:
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "fixture")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "none")
        result = CliRunner().invoke(main, ["run", "handover_block", "--instruction", book.case.instruction,
                                           "--reasoner", "llm", "--seed", "0"])
    assert not book.problems, book.problems
    assert result.exit_code == 0, result.output
    assert "every goal predicate holds at the end" in result.output
