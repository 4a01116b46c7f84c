"""Where a recovery stops short: sub-goals met already, nodes passed before the failure."""

from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.shortcuts import Ahead, Shortcuts, attach_subgoal_checks
from agentchord.expr.compiler import compile_expr
from agentchord.expr.vocabulary import Vocabulary
from agentchord.features.frame import make_static_frame
from agentchord.graph.progress import nominal_path
from agentchord.library import load_task_graph

GRAPH = load_task_graph("single_arm_pour_water")
NOMINAL_NEXT = {GRAPH.edge(e).source: e for e in nominal_path(GRAPH)}


def _program(edge_id: str) -> EdgeProgram:
    return EdgeProgram.from_edge(GRAPH.edge(edge_id))


def _holding(*nodes: str):
    return lambda node: node in nodes


def test_a_nominal_edge_passes_its_target_the_first_tick_it_holds_a_recovery_edge_never():
    shortcuts = Shortcuts()
    shortcuts.observe(_program("e3"), _holding())
    assert shortcuts.passed == set()
    shortcuts.observe(_program("e3"), _holding("v3"))
    shortcuts.observe(_program("e2_r_bottle_dropped"), _holding("r_bottle_regrasped"))
    shortcuts.observe(None, _holding("v4"))
    assert shortcuts.passed == {"v3"}


def test_a_recovery_whose_merge_node_holds_is_met_unless_an_arm_holds_what_it_grasps():
    recovery = _program("e5_r_bottle_dropped")  # regrasp and place: merges at v5
    assert Shortcuts.met_merge(GRAPH, recovery, ["bottle"], [], _holding("v5")) == "v5"
    assert Shortcuts.met_merge(GRAPH, recovery, ["bottle"], [], _holding()) is None
    # Caught again in the hand: the binding judges that hold, not the node.
    assert Shortcuts.met_merge(GRAPH, recovery, ["bottle"], [("right", "bottle")], _holding("v5")) is None
    # A recovery that ends at a recovery node has no sub-goal of the nominal path to meet.
    assert Shortcuts.met_merge(GRAPH, _program("e2_r_bottle_dropped"), ["bottle"], [], _holding("r_bottle_regrasped")) is None
    assert Shortcuts.met_merge(GRAPH, _program("e5"), ["bottle"], [], _holding("v5")) is None


def test_a_merge_goes_on_past_a_passed_node_when_the_node_after_it_holds():
    shortcuts = Shortcuts(passed={"v3"})
    assert shortcuts.ahead(GRAPH, NOMINAL_NEXT, "v2", _holding("v4")) == Ahead("v4", ["v3"], ["e3", "e4"])
    # The node after does not hold (the bottle is not upright in the hand): pour again.
    assert shortcuts.ahead(GRAPH, NOMINAL_NEXT, "v2", _holding()) is None
    # Not passed: nothing to skip, whatever holds.
    assert Shortcuts().ahead(GRAPH, NOMINAL_NEXT, "v2", _holding("v4")) is None


def test_a_merge_never_skips_into_the_goal():
    shortcuts = Shortcuts(passed={"v5"})
    assert shortcuts.ahead(GRAPH, NOMINAL_NEXT, "v4", _holding("v6")) is None


def test_a_recovery_place_is_given_what_its_merge_node_asks_of_its_object():

    towel = load_task_graph("fold_towel")
    program = EdgeProgram.from_edge(towel.edge("e4_r_bl_slipped"))
    vocabulary = Vocabulary(frozenset(towel.objects))
    attach_subgoal_checks(program, [compile_expr(c, vocabulary) for c in towel.node("v4").constraints])
    places = {a.args.obj: a for step in program.steps for a in step if a.name == "place"}
    corner = {"extent": (0.005, 0.005, 0.005)}

    def frame(bl):
        return make_static_frame(objects={"towel_bl": {**corner, "pos": bl}, "towel_tl": {**corner, "pos": (0.0, 0.6, 0.0)},
                                          "towel_br": {**corner, "pos": (0.3, 0.3, 0.0)}, "towel_tr": {**corner, "pos": (0.3, 0.6, 0.0)}})

    # v4 reads towel_bl in two constraints: released, and within 4.5 cm of towel_tl. The far corner
    # (towel_br, 30 cm from its top corner) is not the left place's concern.
    left = places["towel_bl"].meets_subgoal
    assert left(frame((0.0, 0.59, 0.008))) is True
    assert left(frame((0.0, 0.55, 0.008))) is False  # 5 cm short
    held = frame((0.0, 0.59, 0.008))
    held.holding = {("left", "towel_bl")}
    assert left(held) is False


def test_a_place_whose_object_no_merge_constraint_reads_gets_no_check():
    program = _program("e5_r_bottle_dropped")
    attach_subgoal_checks(program, [compile_expr("tilt(cup) - 15", Vocabulary(frozenset(GRAPH.objects)))])
    assert all(a.meets_subgoal is None for step in program.steps for a in step if a.name == "place")
