"""The offline conductor: ground the free keyframes of a graph in the scene (Sec. III-D, Eq. 9).

Most keyframes are fixed by their atomic action and the scene (a grasp on an object, a
pour offset from the cup). Two kinds are free and are synthesised here with the
sub-goal solver (dual annealing + SLSQP, warm-started from the last solution of the same
keyframe): an absolute tool target (``move_to_target``: where to present a cup, where
to hand over, where to park) and an absolute place spot (``place`` with a ``target``
and no ``relative_to``). The cost terms: clearance of the tool and of what it holds
from every other object (a margin), the arm's reach shell, the pull to the rules'
preferred value, consistency with the previous solution. A keyframe that is already
clear stays where it is; an infeasible one keeps its value and is reported.

Edges with path constraints are marked to run the receding-horizon path solver
(``path: solved``) when their motion carries an object near other objects.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from agentchord.agents.scene import Scene, SceneObject
from agentchord.agents.rules.accounts import ARMS, Account, ArmAccount, apply_step
from agentchord.agents.rules.arranger import Arranger
from agentchord.graph.models import ActionCall, Edge, TaskGraph
from agentchord.features.frame import FeatureFrame, make_static_frame
from agentchord.solvers.obstacles import object_spheres, scene_spheres
from agentchord.solvers.subgoal import SubgoalSolver
from agentchord.solvers.subgoal_problem import SubgoalProblem, SubgoalSolution

#: Clearance (m) kept between a keyframe (tool, held or placed object) and other objects.
MARGIN = 0.02
#: How far (m) a free place spot may move from the rules' spot; a spot in a named region
#: stays inside the region.
PLACE_SLACK = 0.08
#: A solution closer than this (m) to the rules' value leaves the value as it is.
KEEP = 0.002


@dataclass
class Keyframe:
    """One synthesised keyframe, for the conductor's report.

    Attributes:
        edge: Edge id.
        arm: The arm.
        action: ``move_to_target`` or ``place``.
        before: The rules' value.
        after: The value written (unchanged when already clear or infeasible).
        feasible: Whether the solver met every hard term.
        method: ``cold`` or ``warm``.
        ms: Solve time.
    """

    edge: str
    arm: str
    action: str
    before: list[float]
    after: list[float]
    feasible: bool
    method: str
    ms: float


@dataclass
class Conductor:
    """Grounds free keyframes; keeps the last solution per keyframe for warm starts.

    Attributes:
        solver: The sub-goal solver.
        report: What the last :meth:`conduct` decided, one entry per free keyframe.
    """

    solver: SubgoalSolver = field(default_factory=lambda: SubgoalSolver(seed=0))
    report: list[Keyframe] = field(default_factory=list)
    _last: dict[str, SubgoalSolution] = field(default_factory=dict, repr=False)

    def conduct(self, graph: TaskGraph, scene: Scene) -> TaskGraph:
        """The graph with its free keyframes solved; structure unchanged."""
        out = graph.model_copy(deep=True)
        objects = {o.name: o for o in scene.objects}
        frame = make_static_frame({o.name: {"pos": o.pos, "quat": o.quat, "axis": o.axis, "extent": o.extent} for o in scene.objects})
        accounts = Arranger(scene).accounts(graph)
        by_source = {graph.edge(e).source: a for e, a in accounts.items()}
        self.report = []
        for edge in out.edges:
            account = accounts.get(edge.id) or by_source.get(edge.source) or {a: ArmAccount() for a in ARMS}
            for index, step in enumerate(edge.steps):
                for arm, call in step.items():
                    if call is None:
                        continue
                    if call.fn == "move_to_target":
                        self._tool_target(edge, index, arm, call, account, objects, frame)
                    elif call.fn == "place" and call.args.get("target") is not None and call.args.get("relative_to") is None:
                        two_arm = sum(1 for c in step.values() if c is not None and c.fn == "place" and c.args.get("obj") == call.args["obj"]) > 1
                        if not two_arm:  # a two-arm carry keeps its one target for both grippers
                            self._place_spot(edge, index, arm, call, objects, scene, frame)
                    if edge.path_constraints and call.fn in ("move_to_obj", "move_to_target") and account[arm].holding:
                        # A carried object under a path constraint: the receding-horizon path solver keeps it clear.
                        call.args["path"] = "solved"
                account = apply_step(account, step)
        return out

    def _tool_target(
        self, edge: Edge, index: int, arm: str, call: ActionCall, account: Account, objects: dict[str, SceneObject], frame: FeatureFrame
    ) -> None:
        held = account[arm].holding
        in_hand = [account[a].holding for a in ARMS if account[a].holding]
        # What the tool carries is centred on it (a side grasp at mid-height).
        carried = {arm: object_spheres(held, frame.objects[held]).translated(-frame.objects[held].pos)} if held in objects else {}
        problem = SubgoalProblem(
            arms=(arm,),
            obstacles=scene_spheres(frame, exclude=in_hand, skip_held=False),
            held=carried,
            preferred={arm: np.asarray(call.args["pos"], dtype=float)},
            margin=MARGIN,
        )
        self._solve(edge, index, arm, call, "pos", problem, lambda p: p)

    def _place_spot(
        self, edge: Edge, index: int, arm: str, call: ActionCall, objects: dict[str, SceneObject], scene: Scene, frame: FeatureFrame
    ) -> None:
        obj = objects.get(call.args["obj"])
        if obj is None:
            return
        height = float(obj.pos[2])
        target = np.array([*call.args["target"], height])
        slack = PLACE_SLACK
        for region in scene.regions:
            if float(np.hypot(target[0] - region.center[0], target[1] - region.center[1])) <= region.radius:
                slack = min(slack, max(0.0, 0.7 * region.radius))
        # Decide the object's centre on the table: a "tool" as wide as the object, at its own height,
        # near the rules' spot (inside its region, if the spot is in one).
        problem = SubgoalProblem(
            arms=(arm,),
            low=np.array([target[0] - slack, target[1] - slack, height - 1e-3]),
            high=np.array([target[0] + slack + 1e-6, target[1] + slack + 1e-6, height + 1e-3]),
            obstacles=scene_spheres(frame, exclude=[obj.name], skip_held=False),
            preferred={arm: target},
            tool_radius=0.5 * float(max(obj.extent[0], obj.extent[1])),
            margin=MARGIN,
        )
        self._solve(edge, index, arm, call, "target", problem, lambda p: p[:2])

    def _solve(self, edge: Edge, index: int, arm: str, call: ActionCall, field_name: str, problem: SubgoalProblem, project) -> None:
        # Keyed by what is asked, so the same keyframe on several edges (and re-conducting after an
        # online repair) warm-starts from the last solution.
        key = f"{arm}/{call.fn}/{call.args.get('obj', '')}/{call.args[field_name]}"
        warm = self._last.get(key)
        start = time.perf_counter()
        solution = self.solver.solve(problem, warm_start=warm)
        ms = 1000.0 * (time.perf_counter() - start)
        before = [float(v) for v in call.args[field_name]]
        after = before
        if solution.feasible:
            self._last[key] = solution
            proposed = [round(float(v), 4) for v in project(solution.positions[arm])]
            if float(np.linalg.norm(np.subtract(proposed, before))) > KEEP:
                after = proposed
                call.args[field_name] = after
        self.report.append(Keyframe(edge.id, arm, call.fn, before, after, solution.feasible, "warm" if warm else "cold", round(ms, 2)))

