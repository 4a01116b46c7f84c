"""Edge programs: steps of per-arm actions, and which arms an action may move out of its way."""

from types import SimpleNamespace

from agentchord.actions.base import ArmAction, Status
from agentchord.execution.edge_program import EdgeProgram


class _Probe(ArmAction):
    """Runs ``ticks`` ticks and records the free arms it sees at each."""

    name = "probe"

    def __init__(self, arm: str, ticks: int) -> None:
        super().__init__(arm, args=None)
        self.ticks = ticks
        self.seen: list[frozenset[str]] = []

    def script(self, robot):
        for _ in range(self.ticks):
            self.seen.append(robot.free_arms)
            yield


def _robot():
    return SimpleNamespace(targets={"left": None, "right": None}, free_arms=frozenset())


def test_an_arm_whose_part_of_the_step_is_done_is_free_for_the_other_arms_action():
    left, right = _Probe("left", 2), _Probe("right", 5)
    program = EdgeProgram("e1", "v1", [[left, right]], "nominal")
    robot = _robot()
    program.initialise(robot)
    statuses = [program.update(robot) for _ in range(6)]
    assert statuses[-1] == Status.SUCCESS
    assert left.seen == [frozenset(), frozenset()]
    # The left probe ends at its third update: from then on the right one sees the left arm free.
    assert right.seen == [frozenset(), frozenset(), frozenset({"left"}), frozenset({"left"}), frozenset({"left"})]


def test_an_arm_with_no_action_in_the_step_is_free_and_none_is_free_outside_an_update():
    right = _Probe("right", 2)
    program = EdgeProgram("e1", "v1", [[right]], "nominal")
    robot = _robot()
    program.initialise(robot)
    program.update(robot)
    assert right.seen == [frozenset({"left"})]
    # Between updates (and for an action run on its own) no arm is free to be moved.
    assert robot.free_arms == frozenset()
