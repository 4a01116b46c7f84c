"""Holds that go wrong in the hand (agentchord.agents.rules.in_hand): the hand-over giver's low grip."""

from __future__ import annotations

from agentchord.agents.rules.arranger import Arranger
from agentchord.expr import Vocabulary, compile_expr
from agentchord.features.frame import make_static_frame
from test_agents_rules_arranger import nominal_only
from test_agents_rules_composer import scene_of


def test_the_giver_of_a_handover_is_watched_for_a_low_grip_until_it_lets_go():
    out = Arranger(scene_of("handover_block")).arrange(nominal_only("handover_block"))
    watched = [e.id for e in out.nominal_edges() if any(f.name == "block_grip_low" for f in e.failures)]
    assert watched == ["e2", "e3"]  # held by the giver at the source, handed over there or later
    mode = next(f for f in out.edge("e2").failures if f.name == "block_grip_low")
    regrip = out.edge(mode.recovery)
    assert [(a, c.fn) for a, c in regrip.calls][:3] == [("left", "place"), ("left", "grasp"), ("left", "move_to_target")]
    assert regrip.steps[1]["left"].args["height"] == 0.85
    compiled = compile_expr(mode.monitor, Vocabulary(objects={"block"}))

    def value(grip_height: float, axis=(0.0, 0.0, 1.0)) -> float:
        frame = make_static_frame(objects={"block": {"pos": (0.0, 0.5, 0.3), "extent": (0.03, 0.03, 0.16), "axis": axis}},
                                  arms={"left": {"ee": (0.0, 0.5, 0.22 + grip_height * 0.16)}}, holding={("left", "block")})
        return compiled(frame)

    assert value(0.5) > 0 and value(0.85) <= 0
    assert value(0.5, axis=(1.0, 0.0, 0.0)) <= 0  # lying in the hand: no high and low
