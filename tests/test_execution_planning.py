"""When each part of the plan arrives: the sequential plan and the pipelined schedule."""

import pytest

from agentchord.agents.replies import branch_nominal_nodes, branch_owners, streamed_tokens
from agentchord.execution.planning import composer_call, pipelined_schedule, sequential_calls
from agentchord.execution.reasoning import LatencyModel, TokenLatencyModel
from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.library import load_task_graph

TASKS = ["single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "fold_towel", "setup_coffee_tray"]


def _graph(task="single_arm_pour_water"):
    return forward_filter(load_task_graph(task)).graph


def _streamed_s(graph, model, item):
    """When ``item`` (a nominal node or edge id) has streamed from the composer's reply."""
    composer = composer_call(graph)
    return min(model.first_token_s(composer) + model.decode_s(streamed_tokens(graph)[item]), model.price(composer))


def _overlap(calls, moment):
    return sum(1 for c in calls if c.start_s <= moment < c.end_s)


@pytest.mark.parametrize("task", TASKS)
def test_the_robot_moves_once_the_first_edge_is_grounded_and_parts_arrive_in_the_order_needed(task):
    graph = _graph(task)
    model = TokenLatencyModel()
    schedule = pipelined_schedule(graph, model)
    path = nominal_path(graph)
    composer = model.price(composer_call(graph))
    assert schedule.first_motion_s == schedule.edge_ready_s[path[0]] < composer  # read from the stream
    assert schedule.first_motion_s < sum(model.price(c) for c in sequential_calls(graph)) / 10
    starts = {c.call.part: c.start_s for c in schedule.calls}
    assert schedule.modes_listed_s[path[0]] < composer  # the arranger starts on the first edge while the composer writes
    for edge_id in path:
        listed = schedule.modes_listed_s[edge_id]
        assert all(schedule.mode_ready_s[(edge_id, f.name)] > listed for f in graph.edge(edge_id).failures)
        # Each call starts only once what it reads has streamed: an edge's modes its nodes, a branch its merge nodes.
        target = graph.edge(edge_id).target
        assert starts[f"{edge_id} failure modes"] >= _streamed_s(graph, model, target) - 1e-9
        for failure in graph.edge(edge_id).failures:
            merges = branch_nominal_nodes(graph, edge_id, failure.name, branch_owners(graph))
            branch = starts[f"{edge_id}/{failure.name} branch"]
            assert branch >= max([listed, *(_streamed_s(graph, model, n) for n in merges)]) - 1e-9
    # Never more calls in flight than the model serves.
    for call in schedule.calls:
        assert _overlap(schedule.calls, call.start_s) <= model.concurrency


def test_a_mode_is_ready_once_its_entry_has_arrived_and_the_rest_of_its_branch_is_waited_for_where_needed():
    graph = _graph()
    schedule = pipelined_schedule(graph, TokenLatencyModel())
    calls = {c.call.part: c for c in schedule.calls}
    entry, rest, branch = (calls[f"e2/bottle_dropped {part}"] for part in ("entry grounded", "rest grounded", "branch"))
    # The entry is grounded while the arranger still writes the rest of the branch ...
    assert branch.start_s < entry.start_s < branch.end_s <= rest.start_s
    assert schedule.mode_ready_s[("e2", "bottle_dropped")] == entry.end_s < rest.end_s
    assert schedule.edge_ready_s["e2_r_bottle_dropped"] == entry.end_s
    # ... and the edges further on arrive with the rest: the robot waits at their source if it gets there first.
    assert schedule.edge_ready_s["r_bottle_regrasped_again"] == rest.end_s
    # A second drop during the regrasp recovers through an edge of the same branch's rest.
    again = schedule.mode_ready_s[("r_bottle_regrasped_again", "bottle_dropped")]
    assert again >= rest.end_s
    assert set(schedule.edge_ready_s) == {e.id for e in graph.edges}


def test_fewer_calls_at_once_or_a_slower_model_delay_the_branches_not_the_order():
    graph = _graph()
    wide = pipelined_schedule(graph, TokenLatencyModel())
    narrow = pipelined_schedule(graph, TokenLatencyModel(concurrency=1))
    slow = pipelined_schedule(graph, TokenLatencyModel(tokens_per_s=30.0))
    for later in (narrow, slow):
        assert later.branches_ready_s("e6") > wide.branches_ready_s("e6")
    one_at_a_time = sorted(narrow.calls, key=lambda c: c.start_s)
    assert all(a.end_s <= b.start_s + 1e-9 for a, b in zip(one_at_a_time, one_at_a_time[1:]))
    assert slow.first_motion_s > wide.first_motion_s


def test_a_flat_model_does_not_stream_and_the_schedule_is_deterministic():
    graph = _graph()
    flat = pipelined_schedule(graph, LatencyModel())
    assert flat.first_motion_s == pytest.approx(14.0)  # the whole nominal graph (7 s), then the first edge's grounding (7 s)
    assert pipelined_schedule(graph, LatencyModel()) == flat
    assert [c.agent for c in sequential_calls(graph)] == ["composer", "arranger", "conductor"]


def test_ticks_count_from_the_first_motion():
    schedule = pipelined_schedule(_graph(), TokenLatencyModel())
    assert schedule.tick_of(schedule.first_motion_s) == 0
    assert schedule.tick_of(schedule.first_motion_s + 1.0) == 50
    assert schedule.tick_of(schedule.first_motion_s + 0.011) == 1  # armed on the first tick at or after it
    assert schedule.tick_of(0.0) == 0


def test_a_failure_before_its_branch_hurries_what_the_branch_still_needs_and_leaves_what_started_before():
    graph = _graph()
    schedule = pipelined_schedule(graph, TokenLatencyModel())
    at = schedule.modes_listed_s["e2"]  # the robot is on e3's way; e3's modes are not even asked yet
    hurried = schedule.hurried(at, "e3", "bottle_dropped")
    assert hurried.hurries[-1].edge_id == "e3" and hurried.hurried(at, "e3", "bottle_dropped").hurries[0] == hurried.hurries[-1]
    # What started before the failure is as it was ...
    before = {(c.call.part, c.start_s, c.end_s) for c in schedule.calls if c.start_s < at}
    assert before == {(c.call.part, c.start_s, c.end_s) for c in hurried.calls if c.start_s < at}
    # ... the hurried branch arrives sooner, and the calls it needs went before every call not hurried that
    # could have started then.
    assert hurried.mode_ready_s[("e3", "bottle_dropped")] < schedule.mode_ready_s[("e3", "bottle_dropped")] - 1.0
    starts = {c.call.part: c.start_s for c in hurried.calls}
    unhurried = {c.call.part: c.start_s for c in schedule.calls}
    assert starts["e3 failure modes"] < unhurried["e3 failure modes"]
    assert starts["e3/bottle_dropped branch"] < unhurried["e3/bottle_dropped branch"]
    assert starts["e3/bottle_dropped branch"] < starts["e3/cup_tipped branch"]
    # Never more calls in flight than the model serves, hurried or not.
    assert all(_overlap(hurried.calls, c.start_s) <= 4 for c in hurried.calls)


def test_a_schedule_without_its_inputs_is_not_hurried():
    schedule = pipelined_schedule(_graph(), TokenLatencyModel())
    bare = type(schedule)(schedule.calls, schedule.first_motion_s, schedule.edge_ready_s, schedule.mode_ready_s)
    assert bare.hurried(5.0, "e3", "bottle_dropped") is bare


@pytest.mark.parametrize("task", ["single_arm_pour_water", "dual_arm_pour_water", "handover_block"])
def test_the_other_arms_way_is_asked_after_its_branch_and_no_mode_waits_for_it(task):
    graph = _graph(task)
    schedule = pipelined_schedule(graph, TokenLatencyModel())
    calls = {c.call.part: c for c in schedule.calls}
    alternatives = [part for part in calls if part.endswith(" alternatives")]
    assert alternatives
    for part in alternatives:  # in a call of its own, once the branch (the entry it goes round) has been written
        mode = part.removesuffix(" alternatives")
        assert calls[part].start_s >= calls[f"{mode} branch"].end_s - 1e-9
        assert calls[f"{mode} alternatives grounded"].start_s >= calls[part].end_s - 1e-9
    for edge, failure in graph.failures():
        if edge.is_recovery:
            continue
        # A mode is recoverable once its own entry is grounded, whenever its entry's alternative comes.
        mode = f"{edge.id}/{failure.name}"
        assert schedule.mode_ready_s[(edge.id, failure.name)] == max(
            calls[f"{mode} entry grounded"].end_s if f"{mode} entry grounded" in calls else 0.0,
            schedule.edge_ready_s[failure.recovery],
        )
    for edge in graph.recovery_edges():
        if edge.alternative_to is not None:
            assert schedule.edge_ready_s[edge.id] > schedule.edge_ready_s[edge.alternative_to]


def test_with_one_call_at_a_time_every_branch_is_written_before_any_alternative():
    # Nothing else to wait for: the composer's whole graph has streamed before the second call starts.
    schedule = pipelined_schedule(_graph("dual_arm_pour_water"), TokenLatencyModel(concurrency=1))
    parts = [c.call.part for c in sorted(schedule.calls, key=lambda c: c.start_s)]
    last_branch = max(k for k, part in enumerate(parts) if part.endswith(" branch"))
    first_alternatives = min(k for k, part in enumerate(parts) if part.endswith(" alternatives"))
    assert last_branch < first_alternatives


def test_a_recovery_that_binds_the_other_arms_way_before_it_arrived_hurries_it():
    graph = _graph()
    schedule = pipelined_schedule(graph, TokenLatencyModel())
    at = schedule.mode_ready_s[("e2", "bottle_dropped")]
    hurried = schedule.hurried(at, "e2", None, recovery_edge="e2_r_bottle_dropped_via_left")
    assert hurried.edge_ready_s["e2_r_bottle_dropped_via_left"] < schedule.edge_ready_s["e2_r_bottle_dropped_via_left"] - 2.0
    starts = {c.call.part: c.start_s for c in hurried.calls}
    unhurried = {c.call.part: c.start_s for c in schedule.calls}
    assert starts["e2/bottle_dropped alternatives"] < unhurried["e2/bottle_dropped alternatives"]
    # Nothing else of the branch is asked again, and no mode arrives later for it than the model allows.
    assert hurried.mode_ready_s[("e2", "bottle_dropped")] == schedule.mode_ready_s[("e2", "bottle_dropped")]
    assert all(_overlap(hurried.calls, c.start_s) <= 4 for c in hurried.calls)
