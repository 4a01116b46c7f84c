"""Actions: one release arm call -> one of our catalogue's actions (the table in the package docs)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from pydantic import ValidationError

from agentchord.graph.catalog import ACTIONS
from agentchord.graph.interop.conventions import (
    CARRY_Z,
    DROPPED_KWARGS,
    PLACE_Z,
    PRE_PLACE_DIS,
    TABLE_XY,
    WORKSPACE,
)
from agentchord.graph.interop.frames import round6
from agentchord.graph.interop.release import (
    holds_after,
    CallContext,
    fmt,
    fmt_vec,
    fn_of,
    kwargs_of,
    is_number,
    RawCall,
    RawStep,
    roll_of,
    Track,
)
from agentchord.graph.loader import format_loc
from agentchord.graph.models import ActionCall


class ActionTranslator:
    """Translates release calls (mixed into the importer: reports through ``error`` / ``note``)."""

    def _scan_orient(self, order: list[str], steps: dict[str, list[RawStep]]) -> None:
        """Grasp modes implied by ``orient_eef`` right after a grasp of the same arm."""
        last: dict[str, RawCall] = {}
        for edge_id in order:
            for step in steps[edge_id]:
                for arm, raw in step.items():
                    if raw is None or not isinstance(raw.call, dict):
                        continue
                    prev = last.get(arm)
                    kwargs = kwargs_of(raw)
                    if raw.call.get("fn") == "orient_eef" and prev is not None and prev.call.get("fn") == "grasp":
                        obj = kwargs_of(prev).get("obj_name")
                        direction = kwargs.get("direction", "front")
                        mode = {"down": "top", "front": "side"}.get(direction) if isinstance(direction, str) else None
                        if isinstance(obj, str) and mode is not None:
                            self.grasp_modes[(arm, self.renames.get(obj, obj))] = mode
                    last[arm] = raw

    def _translate(
        self, steps: list[RawStep], continuation: list[RawStep], holds: dict[str, str],
        track: Track | None = None,
    ) -> list[dict[str, ActionCall | None]]:
        """Our steps for ``steps``; ``continuation`` is what runs after them.

        ``track`` (each arm's history before ``steps``) is brought up to date in place.
        """
        out: list[dict[str, ActionCall | None]] = []
        holds = dict(holds)
        track = track if track is not None else Track()
        for k, step in enumerate(steps):
            ours: dict[str, ActionCall | None] = {}
            for arm, raw in step.items():
                if raw is None:
                    continue
                after = steps[k + 1:] + continuation
                nxt = next((s[arm] for s in after if s.get(arm) is not None), None)
                ctx = CallContext(arm, nxt, track.before.get(arm), track.previous.get(arm), holds, arm in track.turned)
                call = self._call(raw, ctx)
                track.before[arm] = raw
                if call is not None:
                    ours[arm] = call
                    track.update(arm, call)
            if ours:
                out.append(ours)
                holds = holds_after(holds, [ours])
        return out

    def _call(self, raw: RawCall, ctx: CallContext) -> ActionCall | None:
        arm = ctx.arm
        f, path = raw.file, raw.path
        call = raw.call
        fn = call.get("fn")
        self._unknown_keys(f, path, call, ("fn", "kwargs"))
        kwargs = call.get("kwargs", {})
        if kwargs is None:
            kwargs = {}
        if not isinstance(fn, str) or not isinstance(kwargs, dict):
            self.error(f, path, f"expected {{fn: NAME, kwargs: {{...}}}}, got {call!r}")
            return None
        kwargs = dict(kwargs)
        kpath = f"{path}.kwargs"
        robot = kwargs.pop("robot_name", None)
        if robot is not None:
            mapped = self._arm(robot, f, f"{kpath}.robot_name")
            if mapped is not None and mapped != arm:
                self.error(f, f"{kpath}.robot_name", f"{robot!r} in the {arm} arm's slot")
                return None
        for key, why in DROPPED_KWARGS.items():
            if key in kwargs:
                kwargs.pop(key)
                self.note(f, f"{kpath}.{key}", f"dropped: {why}")
        handler = getattr(self, f"_fn_{fn}", None)
        if handler is None:
            known = ", ".join(sorted(n[4:] for n in dir(self) if n.startswith("_fn_")))
            self.error(f, f"{path}.fn", f"cannot map release action {fn!r}; mapped actions: {known}")
            return None
        before = len(self.problems)
        result = handler(kwargs, raw, ctx)
        if len(self.problems) > before or result is None:
            return None
        for key in kwargs:  # the handlers pop what they map
            self.error(f, f"{kpath}.{key}", f"cannot map kwarg {key!r} of {fn}")
        if kwargs:
            return None
        ours_fn, args = result
        try:
            ACTIONS[ours_fn].args.model_validate(args)
        except ValidationError as error:
            for detail in error.errors(include_url=False):
                self.error(f, kpath, f"{ours_fn}.{format_loc(detail['loc'])}: {detail['msg']} (mapped from {fn})")
            return None
        return ActionCall(fn=ours_fn, args=args)

    def _obj_kwarg(self, kwargs: dict, raw: RawCall, fn: str) -> str | None:
        obj = kwargs.pop("obj_name", None)
        if not isinstance(obj, str) or not obj:
            self.error(raw.file, f"{raw.path}.kwargs.obj_name", f"{fn} needs obj_name (a string), got {obj!r}")
            return None
        return self._object(obj, raw.file, f"{raw.path}.kwargs.obj_name")

    def _numbers(self, kwargs: dict, raw: RawCall, names: Iterable[str], default: float | None = 0.0,
                 ) -> dict[str, float | None] | None:
        """Pop numeric kwargs (``None`` where absent and no default); ``None`` if one is not a number."""
        out: dict[str, float | None] = {}
        ok = True
        for name in names:
            value = kwargs.pop(name, default)
            if (value is not None or default is not None) and not is_number(value):  # null only where it may be
                self.error(raw.file, f"{raw.path}.kwargs.{name}", f"expected a number, got {value!r}")
                ok = False
            out[name] = None if value is None or not ok else float(value)
        return out if ok else None

    def _fn_grasp(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "grasp")
        pre = kwargs.pop("pre_grasp_dis", None)
        if raw.extra.get("pre_grasp_dis") is not None:  # a recovery step's own pre_grasp_dis wins
            pre = raw.extra["pre_grasp_dis"]
        if obj is None:
            return None
        args: dict[str, Any] = {"obj": obj}
        if pre is not None:
            if not is_number(pre):
                self.error(raw.file, f"{raw.path}.kwargs.pre_grasp_dis", f"expected a number (m), got {pre!r}")
                return None
            args["pre_grasp_dis"] = float(pre)
        mode = self.grasp_modes.get((ctx.arm, obj))
        if mode is not None:
            args["mode"] = mode
            self.note(raw.file, raw.path, f"grasp mode {mode!r}: the release orients this arm's tool "
                                          f"{'down' if mode == 'top' else 'front'} right after grasping {obj}")
        if raw.extra.get("skip_if_held"):
            args["skip_if_held"] = True
        return "grasp", args

    def _fn_move_relative_to_object(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "move_relative_to_object")
        d = self._numbers(kwargs, raw, ("x_offset", "y_offset", "z_offset"))
        if obj is None or d is None:
            return None
        offset = self.frame.vector((d["x_offset"], d["y_offset"], d["z_offset"]))
        held = ctx.holds.get(ctx.arm)
        if held is not None and fn_of(ctx.nxt) == "open_gripper":
            # The release lowers what it holds to this offset and lets go there: a place. Ours
            # carries it above the spot; the open_gripper after it becomes our place.
            carry = [offset[0], offset[1], PRE_PLACE_DIS]
            self.note(raw.file, raw.path,
                      f"offset {fmt_vec(offset)} then open_gripper: the release sets {held} down there; our "
                      f"move_to_obj carries it to {fmt_vec(carry)} from {obj}'s top point (the release's "
                      f"pre_place_dis stand-off) and the open_gripper becomes our place")
            return "move_to_obj", {"obj": obj, "offset": carry, "keep_orientation": True}
        args: dict[str, Any] = {"obj": obj, "offset": list(offset)}
        roll = roll_of(ctx.nxt)
        horizontal = math.hypot(offset[0], offset[1])
        if roll and horizontal > 1e-6:
            ox, oy = offset[0] / horizontal, offset[1] / horizontal
            # Negative roll tips the top toward the tool's +y, positive toward -y; tool y = z x approach.
            approach = (-oy, ox) if roll < 0 else (oy, -ox)
            args["yaw"] = round(math.degrees(math.atan2(approach[1], approach[0])), 1)
            self.note(raw.file, raw.path,
                      f"yaw {args['yaw']:g}: approach perpendicular to the offset so that the next "
                      f"rotate_eef ({fmt(roll)} deg) tips the held object toward {obj}")
        else:
            args["keep_orientation"] = True
        self.note(raw.file, raw.path, f"offset {fmt_vec(offset)} in our frame, measured from {obj}'s top point "
                                      "(the release's: from its base-pose origin)")
        return "move_to_obj", args

    def _fn_move_to_absolute_position(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("x", "y", "z"), default=None)
        if d is None:
            return None
        for key in ("x", "y"):
            if d[key] is None:
                self.error(raw.file, f"{raw.path}.kwargs.{key}", f"{key}: null or missing (keep the current {key}) "
                           "cannot be mapped: our move_to_target needs a full position")
        if d["x"] is None or d["y"] is None:
            return None
        if d["z"] is None:
            d["z"] = CARRY_Z
            self.note(raw.file, f"{raw.path}.kwargs.z", f"null (keep the current height) -> z = {CARRY_Z} m, "
                                                        "our carrying height")
        pos = self.frame.point((d["x"], d["y"], d["z"]))
        clipped = tuple(round6(min(max(v, lo), hi)) for v, lo, hi in zip(pos, *WORKSPACE))
        if clipped != pos:
            self.note(raw.file, raw.path, f"position {fmt_vec(pos)} clipped to our workspace: {fmt_vec(clipped)}")
        self.note(raw.file, raw.path, f"({fmt(d['x'])}, {fmt(d['y'])}, {fmt(d['z'])}) in the release's frame "
                                      f"-> {fmt_vec(clipped)} in ours")
        return "move_to_target", {"pos": list(clipped)}

    def _fn_move_by_relative_offset(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("dx", "dy", "dz"))
        mode = kwargs.pop("mode", "extrinsic")
        if d is None:
            return None
        if mode == "extrinsic":
            return "move_by_offset", {"offset": list(self.frame.vector((d["dx"], d["dy"], d["dz"])))}
        if mode == "intrinsic":
            if d["dx"] or d["dy"]:
                self.error(raw.file, f"{raw.path}.kwargs",
                           "an intrinsic dx/dy cannot be mapped: the release's tool x/y axes are not ours "
                           "(only dz, along the approach, is)")
                return None
            self.note(raw.file, raw.path, "intrinsic dz (the release's approach axis, tool z) -> our tool x")
            return "move_by_offset", {"offset": [d["dz"], 0.0, 0.0], "frame": "intrinsic"}
        self.error(raw.file, f"{raw.path}.kwargs.mode", f"expected 'extrinsic' or 'intrinsic', got {mode!r}")
        return None

    def _fn_rotate_eef(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("degree",))
        if d is None:
            return None
        return "rotate_eef", {"angle": d["degree"]}

    def _fn_place_on_table(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "place_on_table")
        d = self._numbers(kwargs, raw, ("x", "y"), default=None)
        if "pre_place_dis" in kwargs:
            kwargs.pop("pre_place_dis")
            self.note(raw.file, f"{raw.path}.kwargs.pre_place_dis",
                      "dropped: our place lowers from the carrying height, no stand-off parameter")
        if obj is None or d is None:
            return None
        args: dict[str, Any] = {"obj": obj, **self._place_yaw(raw, ctx, obj)}
        if d["x"] is None and d["y"] is None:
            return "place", args
        if d["x"] is None or d["y"] is None:
            self.error(raw.file, f"{raw.path}.kwargs", "only one of x, y is given: our place needs both or neither")
            return None
        x, y, _ = self.frame.point((d["x"], d["y"], 0.0))
        (x_lo, y_lo), (x_hi, y_hi) = TABLE_XY
        target = (round6(min(max(x, x_lo), x_hi)), round6(min(max(y, y_lo), y_hi)))
        if target != (x, y):
            self.note(raw.file, raw.path, f"place target ({fmt(x)}, {fmt(y)}) clipped to our table: "
                                          f"({fmt(target[0])}, {fmt(target[1])})")
        self.note(raw.file, raw.path, f"place ({fmt(d['x'])}, {fmt(d['y'])}) in the release's frame -> "
                                      f"({fmt(target[0])}, {fmt(target[1])}) in ours (the object's centre)")
        args["target"] = list(target)
        return "place", args

    def _fn_back_to_initial_pose(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        return "back", {}

    def _fn_open_gripper(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        held = ctx.holds.get(ctx.arm)
        if held is None or fn_of(ctx.before) != "move_relative_to_object":
            return "open_gripper", {}
        # The move before it took what the arm holds to its release point: place it there.
        move = kwargs_of(ctx.before)
        ref = move.get("obj_name")
        ref = self.renames.get(ref, ref) if isinstance(ref, str) else None  # a list or dict is not a name
        d = {k: move.get(k, 0.0) for k in ("x_offset", "y_offset", "z_offset")}
        if not isinstance(ref, str) or not all(is_number(v) for v in d.values()):
            return "open_gripper", {}  # the move itself reports what is wrong with it
        dx, dy, _ = self.frame.vector((d["x_offset"], d["y_offset"], 0.0))
        args: dict[str, Any] = {"obj": held, "target": [dx, dy], "relative_to": ref}
        z = round6(min(max(float(d["z_offset"]), PLACE_Z[0]), PLACE_Z[1]))
        if z:
            args["z_offset"] = z
        args.update(self._place_yaw(raw, ctx, held))
        self.note(raw.file, raw.path,
                  f"open_gripper after move_relative_to_object({ref}) while holding {held}: the release's place by "
                  f"release -> place({held}, target ({fmt(dx)}, {fmt(dy)}) from {ref}'s centre"
                  f"{f', z_offset {fmt(z)}' if z else ''}): ours lowers {held} onto the table, opens, backs off")
        return "place", args

    def _fn_close_gripper(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        return "close_gripper", {}

    def _fn_orient_eef(self, kwargs: dict, raw: RawCall, ctx: CallContext) -> tuple[str, dict] | None:
        direction = kwargs.pop("direction", "front")
        if direction not in ("down", "front"):
            self.error(raw.file, f"{raw.path}.kwargs.direction", f"expected 'down' or 'front', got {direction!r}")
            return None
        held = ctx.holds.get(ctx.arm)
        if ctx.previous == "grasp" and held is not None and (ctx.arm, held) in self.grasp_modes:
            self.note(raw.file, raw.path, f"orient_eef {direction!r} -> zero move_by_offset (hold): the grasp before "
                                          f"it takes {held} with mode {self.grasp_modes[(ctx.arm, held)]!r}")
            return "move_by_offset", {}
        pitch = 90.0 if direction == "down" else -90.0
        self.note(raw.file, raw.path, f"orient_eef {direction!r} -> move_by_offset angles (0, {fmt(pitch)}, 0) "
                                      f"intrinsic: assumes a {'level' if direction == 'down' else 'top-down'} tool")
        return "move_by_offset", {"angles": [0.0, pitch, 0.0], "frame": "intrinsic"}

    def _place_yaw(self, raw: RawCall, ctx: CallContext, obj: str) -> dict[str, float]:
        """``{"yaw": ...}`` for a place of ``obj`` held as the release's ``orient_eef 'down'`` left it, else ``{}``.

        That orientation is absolute (tool x along the release's x, fingers closing along its y), so a
        thin object grasped across its narrow side is carried with its long axis along the release's
        x; our top grasp keeps the object's own yaw and only a place can set it.
        """
        if self.grasp_modes.get((ctx.arm, obj)) != "top" or ctx.turned:
            return {}
        ax, ay, _ = self.frame.vector((1.0, 0.0, 0.0))
        yaw = round6((math.degrees(math.atan2(ay, ax)) + 90.0) % 180.0 - 90.0)  # a long axis: mod 180
        yaw = 90.0 if yaw == -90.0 else yaw
        self.note(raw.file, raw.path,
                  f"place yaw {fmt(yaw)}: the release's orient_eef 'down' is absolute (its tool x forward, fingers "
                  f"closing along its y), so {obj}, grasped across its narrow side, lies along the release's x")
        return {"yaw": yaw}
