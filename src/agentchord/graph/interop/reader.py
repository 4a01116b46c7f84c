"""Reading the release files: bounded JSON, the task graph's chain of edges, the recovery
spec's bindings, monitors and recovery steps."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from agentchord.graph.interop.conventions import DROPPED_KWARGS, SLOTS
from agentchord.graph.interop.release import Binding, is_number, RawCall, RawStep
from agentchord.guard.documents import check_shape, read_text
from agentchord.guard.exceptions import DocumentError
from agentchord.guard.numbers import describe, non_finite


def read_json(path: Path, problems: list[str]) -> Any:
    # Bounded like every input (agentchord.guard): regular files, size, depth, finite numbers.
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError, DocumentError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
        problems.append(f"{path}: (file): cannot read the file: {reason}")
        return None
    try:
        data = json.loads(text)
    except RecursionError:
        problems.append(f"{path}: (file): the JSON is nested too deeply to read")
        return None
    except json.JSONDecodeError as error:
        problems.append(f"{path}: (file): line {error.lineno}, column {error.colno}: invalid JSON: {error.msg}")
        return None
    try:
        check_shape(data)
    except DocumentError as error:
        problems.append(f"{path}: {error.where or '(file)'}: {error}")
        return None
    bad = [f"{path}: {where or '(top level)'}: {describe(number)}" for where, number in non_finite(data)]
    if bad:
        problems += bad
        return None
    return data




class ReleaseReader:
    """Reads the two files (mixed into the importer: reports through ``error`` / ``note``)."""

    def _chain(self, data: Any) -> tuple[list[dict], list[dict], str, str, str] | None:
        f = self.gfile
        if not isinstance(data, dict):
            self.error(f, "(top level)", f"expected a task graph object, found {type(data).__name__}")
            return None
        self._unknown_keys(f, "", data, ("task", "start", "goal", "nodes", "edges", "max_transitions"))
        for key in ("task", "start", "goal"):
            if not isinstance(data.get(key), str) or not data.get(key):
                self.error(f, key, f"missing or not a non-empty string: {data.get(key)!r}")
        if "max_transitions" in data:
            self.note(f, "max_transitions", "dropped: our executor's tick limit and failure budgets bound an episode")
        nodes, edges = data.get("nodes"), data.get("edges")
        if not isinstance(nodes, list) or not nodes:
            self.error(f, "nodes", "missing or not a non-empty list")
            nodes = []
        if not isinstance(edges, list) or not edges:
            self.error(f, "edges", "missing or not a non-empty list")
            edges = []
        node_ids: list[str] = []
        for i, node in enumerate(nodes):
            if not isinstance(node, dict) or not isinstance(node.get("id"), str):
                self.error(f, f"nodes[{i}]", "expected an object with a string id")
                continue
            self._unknown_keys(f, f"nodes[{i}]", node, ("id", "semantic"))
            if node["id"] in node_ids:
                self.error(f, f"nodes[{i}].id", f"duplicate node id {node['id']!r}")
            node_ids.append(node["id"])
            if not isinstance(node.get("semantic", ""), str):
                self.error(f, f"nodes[{i}].semantic", "not a string")
        out: dict[str, dict] = {}
        edge_ids: set[str] = set()
        for i, edge in enumerate(edges):
            if not isinstance(edge, dict):
                self.error(f, f"edges[{i}]", f"expected an edge object, found {type(edge).__name__}")
                continue
            self._unknown_keys(f, f"edges[{i}]", edge, ("id", "source", "target", *SLOTS))
            for key in ("id", "source", "target"):
                if not isinstance(edge.get(key), str):
                    self.error(f, f"edges[{i}].{key}", f"missing or not a string: {edge.get(key)!r}")
            if not all(isinstance(edge.get(k), str) for k in ("id", "source", "target")):
                continue
            if edge["id"] in edge_ids:
                self.error(f, f"edges[{i}].id", f"duplicate edge id {edge['id']!r}")
            edge_ids.add(edge["id"])
            for key in ("source", "target"):
                if edge[key] not in node_ids:
                    self.error(f, f"edges[{i}].{key}", f"unknown node {edge[key]!r}")
            if edge["source"] in out:
                self.error(f, f"edges[{i}].source",
                           f"a second edge leaves {edge['source']!r}: the release format is one start-to-goal chain")
            out[edge["source"]] = edge
        if self.problems:
            return None
        # Follow the chain from start to goal; every edge must be on it.
        order, node, seen = [], data["start"], {data["start"]}
        if data["start"] not in node_ids:
            self.error(f, "start", f"unknown node {data['start']!r}")
        if data["goal"] not in node_ids:
            self.error(f, "goal", f"unknown node {data['goal']!r}")
        while node != data["goal"] and node in out:
            edge = out[node]
            order.append(edge)
            node = edge["target"]
            if node in seen:
                self.error(f, f"edges[{edges.index(edge)}].target", f"the chain loops back to {node!r}")
                return None
            seen.add(node)
        if node != data["goal"]:
            self.error(f, "goal", f"the chain from {data['start']!r} stops at {node!r} and never reaches the goal")
        for i, edge in enumerate(edges):
            if edge not in order:
                self.error(f, f"edges[{i}]", f"edge {edge['id']!r} is not on the start-to-goal chain")
        if self.problems:
            return None
        return nodes, order, data["start"], data["goal"], data["task"]

    def _edge_steps(self, edge: dict, index: int) -> list[RawStep]:
        step = self._slots(self.gfile, f"edges[{index}]", edge)
        if all(v is None for v in step.values()):
            self.error(self.gfile, f"edges[{index}]", "both left_arm_action and right_arm_action are null")
            return []
        return [step]

    def _slots(self, file: str, path: str, holder: dict) -> RawStep:
        step: RawStep = {}
        for slot, arm in SLOTS.items():
            call = holder.get(slot)
            if call is None:
                continue
            if not isinstance(call, dict):
                self.error(file, f"{path}.{slot}", f"expected {{fn, kwargs}} or null, found {type(call).__name__}")
                continue
            step[arm] = RawCall(call, file, f"{path}.{slot}")
        return step


    # --------------------------------------------------------- recovery spec
    def _bindings(self, data: Any, steps: dict[str, list[RawStep]], release_task: str) -> list[Binding]:
        f = self.sfile
        if not isinstance(data, dict):
            self.error(f, "(top level)", f"expected a recovery spec object, found {type(data).__name__}")
            return []
        self._unknown_keys(f, "", data, ("task", "recovery_bindings"))
        if data.get("task") not in (None, release_task):
            self.note(f, "task", f"{data.get('task')!r} differs from the task graph's {release_task!r}")
        raw = data.get("recovery_bindings")
        if not isinstance(raw, list):
            self.error(f, "recovery_bindings", "missing or not a list")
            return []
        bindings, names = [], set()
        for i, b in enumerate(raw):
            path = f"recovery_bindings[{i}]"
            if not isinstance(b, dict):
                self.error(f, path, f"expected a binding object, found {type(b).__name__}")
                continue
            self._unknown_keys(f, path, b, ("edge_id", "failure_name", "monitors", "recovery", "merge",
                                            "repeat_until_success"))
            edge_id, name = b.get("edge_id"), b.get("failure_name")
            if not isinstance(edge_id, str) or edge_id not in steps:
                self.error(f, f"{path}.edge_id", f"unknown edge {edge_id!r}; the task graph has {', '.join(steps)}")
                continue
            if not isinstance(name, str) or not name:
                self.error(f, f"{path}.failure_name", f"missing or not a non-empty string: {name!r}")
                continue
            if (edge_id, name) in names:
                self.error(f, f"{path}.failure_name", f"duplicate failure {name!r} on edge {edge_id!r}")
                continue
            names.add((edge_id, name))
            merge = b.get("merge", "target")
            if merge not in ("target", "source"):
                self.error(f, f"{path}.merge", f"expected 'target' or 'source', got {merge!r}")
            repeat = b.get("repeat_until_success", False)
            if not isinstance(repeat, bool):
                self.error(f, f"{path}.repeat_until_success", f"expected true or false, got {repeat!r}")
            elif repeat:
                self.note(f, f"{path}.repeat_until_success",
                          "mapped to re-entry monitors on the recovery edge, bounded by the failure budget "
                          "(3 fires per edge and mode), not unbounded repetition")
            monitors = self._monitors(b.get("monitors"), f"{path}.monitors")
            rec_steps, intent = self._recovery_steps(b.get("recovery"), f"{path}.recovery", edge_id, steps)
            bindings.append(Binding(i, edge_id, name, monitors, rec_steps, merge, repeat is True, intent))
        return bindings

    def _monitors(self, raw: Any, path: str) -> list[tuple[str, dict[str, Any]]]:
        f = self.sfile
        if not isinstance(raw, list) or not raw:
            self.error(f, path, "missing or not a non-empty list of monitors")
            return []
        out = []
        for j, m in enumerate(raw):
            where = f"{path}[{j}]"
            if not isinstance(m, dict):
                self.error(f, where, f"expected a monitor object, found {type(m).__name__}")
                continue
            kind = m.get("type")
            if kind == "object_moved":
                self._unknown_keys(f, where, m, ("type", "objects", "threshold"))
                objs = m.get("objects")
                if not isinstance(objs, list) or not objs or not all(isinstance(o, str) for o in objs):
                    self.error(f, f"{where}.objects", f"expected a non-empty list of object names, got {objs!r}")
                    continue
                threshold = m.get("threshold")
                if threshold is None:
                    threshold = 0.02
                    self.note(f, where, "no threshold: drift tolerance 0.02 m (the library graphs')")
                elif not is_number(threshold) or threshold <= 0:
                    self.error(f, f"{where}.threshold", f"expected a positive number (m), got {threshold!r}")
                    continue
                names = [self._object(o, f, f"{where}.objects[{k}]") for k, o in enumerate(objs)]
                out.append(("object_moved", {"objects": names, "threshold": float(threshold)}))
            elif kind == "hold_lost":
                self._unknown_keys(f, where, m, ("type", "robot_name", "obj_name", "threshold"))
                arm = self._arm(m.get("robot_name"), f, f"{where}.robot_name")
                obj = m.get("obj_name")
                if not isinstance(obj, str):
                    self.error(f, f"{where}.obj_name", f"missing or not a string: {obj!r}")
                    continue
                if "threshold" in m:
                    self.note(f, f"{where}.threshold",
                              "dropped: our hold monitor is contact-based (holding), debounced by the 3-tick window")
                if arm is not None:
                    out.append(("hold_lost", {"arm": arm, "obj": self._object(obj, f, f"{where}.obj_name")}))
            else:
                self.error(f, f"{where}.type", f"unknown monitor type {kind!r}; known: object_moved, hold_lost")
        return out

    def _recovery_steps(
        self, raw: Any, path: str, failed: str, steps: dict[str, list[RawStep]]
    ) -> tuple[list[RawStep], str]:
        f = self.sfile
        if not isinstance(raw, list) or not raw:
            self.error(f, path, "missing or not a non-empty list of recovery steps")
            return [], ""
        out: list[RawStep] = []
        intents = []
        for j, s in enumerate(raw):
            where = f"{path}[{j}]"
            if not isinstance(s, dict):
                self.error(f, where, f"expected a recovery step object, found {type(s).__name__}")
                continue
            kind = s.get("type")
            if s.get("force_valid") is not None:
                self.note(f, f"{where}.force_valid", f"dropped: {DROPPED_KWARGS['force_valid']}")
            pre = s.get("pre_grasp_dis")
            if pre is not None and not is_number(pre):
                self.error(f, f"{where}.pre_grasp_dis", f"expected a number (m), got {pre!r}")
                continue
            extra = {"pre_grasp_dis": pre} if pre is not None else {}
            common = ("type", "force_valid", "pre_grasp_dis")
            if kind == "regrasp":
                self._unknown_keys(f, where, s, (*common, "robot_name", "obj_name"))
                arm = self._arm(s.get("robot_name"), f, f"{where}.robot_name")
                if not isinstance(s.get("obj_name"), str):
                    self.error(f, f"{where}.obj_name", f"missing or not a string: {s.get('obj_name')!r}")
                    continue
                if arm is not None:
                    call = {"fn": "grasp", "kwargs": {"obj_name": s["obj_name"], **extra}}
                    out.append({arm: RawCall(call, f, where)})
                    intents.append("regrasp")
            elif kind == "regrasp_both":
                self._unknown_keys(f, where, s, (*common, "arms"))
                arms = s.get("arms")
                if not isinstance(arms, dict) or not arms:
                    self.error(f, f"{where}.arms", f"expected {{left_arm: obj, right_arm: obj}}, got {arms!r}")
                    continue
                step: RawStep = {}
                for release_arm, obj in arms.items():
                    arm = self._arm(release_arm, f, f"{where}.arms.{release_arm}")
                    if not isinstance(obj, str):
                        self.error(f, f"{where}.arms.{release_arm}", f"expected an object name, got {obj!r}")
                    elif arm is not None:
                        call = {"fn": "grasp", "kwargs": {"obj_name": obj, **extra}}
                        step[arm] = RawCall(call, f, f"{where}.arms.{release_arm}", {"skip_if_held": True})
                if step:
                    out.append(step)
                    intents.append("regrasp both")
                    self.note(f, where, "synchronous grasp of both arms with skip_if_held: true "
                                        "(an arm still holding its object keeps it)")
            elif kind in ("retry_failed_edge", "replay_edge"):
                self._unknown_keys(f, where, s, (*common, "edge_id") if kind == "replay_edge" else common)
                edge_id = failed if kind == "retry_failed_edge" else s.get("edge_id")
                if not isinstance(edge_id, str) or edge_id not in steps:
                    known = ", ".join(steps)
                    self.error(f, f"{where}.edge_id", f"unknown edge {edge_id!r}; the task graph has {known}")
                    continue
                for replayed in steps[edge_id]:
                    out.append({arm: None if raw_call is None else RawCall(raw_call.call, raw_call.file, raw_call.path,
                                                                          dict(extra))
                                for arm, raw_call in replayed.items()})
                intents.append("retry" if kind == "retry_failed_edge" else f"replay {edge_id}")
            elif kind == "action":
                self._unknown_keys(f, where, s, (*common, *SLOTS))
                step = self._slots(f, where, s)
                if not step:
                    self.error(f, where, "both left_arm_action and right_arm_action are missing or null")
                    continue
                out.append(step)
                intents.append("action")
            else:
                known = "regrasp, regrasp_both, retry_failed_edge, replay_edge, action"
                self.error(f, f"{where}.type", f"unknown recovery step type {kind!r}; known: {known}")
        return out, ", then ".join(intents)
