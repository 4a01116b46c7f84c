"""The simulated world's cameras: depth and instance segmentation rendered with MuJoCo.

Each :class:`DepthCamera` has its own ``mujoco.Renderer`` (EGL headless) and gives
:class:`~agentchord.worlds.protocol.CameraFrame` s: depth along the viewing axis, the
camera's geometry, and per-pixel object labels (the simulator's own segmentation).
"""

from __future__ import annotations

import mujoco
import numpy as np

from agentchord.worlds.protocol import CameraFrame
from agentchord.sim.renderers import close_at_exit, closed, open_renderer

class DepthCamera:
    """A scene camera that renders depth and segmentation with its own ``mujoco.Renderer``
    (a :class:`~agentchord.worlds.protocol.Camera` of the simulated world).

    Both images come from one render pass when the renderer's GL context is
    reachable (segmentation colours and the depth buffer of the same pass),
    else from two passes with the public ``enable_*_rendering`` switches.

    Args:
        model: The compiled model.
        camera: Name of a camera of the model.
        width: Image width (px).
        height: Image height (px).
        object_names: The objects whose pixels the frame's ``labels`` name (their index here).
        data: The simulation state :meth:`capture` renders by default.
    """

    def __init__(self, model: mujoco.MjModel, camera: str, width: int = 320, height: int = 240,
                 object_names: list[str] | tuple[str, ...] = (), data: mujoco.MjData | None = None) -> None:
        self.model = model
        self.data = data
        self.name = camera
        self.camera = camera
        self.camera_id = model.camera(camera).id
        self.width, self.height = width, height
        self.renderer = open_renderer(model, height, width)
        self.option = mujoco.MjvOption()
        self.option.sitegroup[:] = 0  # sites (the TCP markers) are not scene surfaces
        extent = model.stat.extent
        znear = np.float32(model.vis.map.znear * extent)
        zfar = np.float32(model.vis.map.zfar * extent)
        c_coef = -(zfar + znear) / (zfar - znear)
        d_coef = -(np.float32(2) * zfar * znear) / (zfar - znear)
        # Reversed-Z depth buffer (the renderer's readDepthMap = ZEROFAR).
        self._c = float(np.float32(-0.5) * c_coef - np.float32(0.5))
        #: Depth at or beyond which a pixel saw nothing (the far clipping plane).
        self.far = float(model.vis.map.zfar * extent)
        # Geom id -> index of its object in ``object_names`` (every geom of the object's body), -1: none.
        self._geom_label = np.full(model.ngeom + 1, -1, dtype=np.int32)  # index: geom id + 1
        for index, name in enumerate(object_names):
            for geom in np.nonzero(model.geom_bodyid == model.body(name).id)[0]:
                self._geom_label[geom + 1] = index
        self._d = float(np.float32(-0.5) * d_coef)
        r = self.renderer
        self.single_pass = all(hasattr(r, a) for a in ("_rect", "_mjr_context", "_gl_context"))
        self._rgb = np.empty((height, width, 3), dtype=np.uint8)
        self._zbuf = np.empty((height, width), dtype=np.float32)
        close_at_exit(self)

    def render(self, data: mujoco.MjData | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Depth (H, W) float32 and MuJoCo's segmentation (H, W, 2) int32 (object id, object type;
        -1 for the background) of the state ``data``, default the world's the camera was opened on."""
        data = data if data is not None else self.data
        if data is None:
            raise ValueError(f"camera {self.camera!r}: no simulation state to render (pass data)")
        r = self.renderer
        if r is None:
            raise RuntimeError(f"camera {self.camera!r} was closed")
        r.update_scene(data, camera=self.camera_id, scene_option=self.option)
        if self.single_pass:
            return self._render_single_pass()
        # pragma: no cover - depends on the mujoco version's internals
        r.enable_depth_rendering()
        depth = r.render()
        r.enable_segmentation_rendering()
        seg = r.render()
        r.disable_segmentation_rendering()
        return depth, seg

    def capture(self, data: mujoco.MjData | None = None) -> CameraFrame:
        """A frame of the current state: depth, the camera's geometry, object labels."""
        depth, seg = self.render(data)
        data = data if data is not None else self.data
        return CameraFrame(
            camera=self.camera,
            depth=depth,
            fovy=float(self.model.cam_fovy[self.camera_id]),
            pos=data.cam_xpos[self.camera_id].copy(),
            rot=data.cam_xmat[self.camera_id].reshape(3, 3).copy(),
            far=self.far,
            labels=self._labels(seg),
        )

    def _labels(self, seg: np.ndarray) -> np.ndarray:
        """Per pixel, the index of the object its geom belongs to; -1 for anything else."""
        ids = seg[..., 0]
        is_geom = seg[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
        ids = np.where(is_geom & (ids >= 0) & (ids < len(self._geom_label) - 1), ids, -1)
        return self._geom_label[ids + 1]

    def _render_single_pass(self) -> tuple[np.ndarray, np.ndarray]:
        r = self.renderer
        scene = r.scene
        flags = scene.flags.copy()
        scene.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = True
        scene.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = True
        if r._gl_context:
            r._gl_context.make_current()
        mujoco.mjr_render(r._rect, scene, r._mjr_context)
        mujoco.mjr_readPixels(self._rgb, self._zbuf, r._rect, r._mjr_context)
        np.copyto(scene.flags, flags)
        depth = (self._d / (self._zbuf.astype(np.float64) + self._c)).astype(np.float32)
        rgb = self._rgb.astype(np.int32)
        segid = rgb[..., 0] + (rgb[..., 1] << 8) + (rgb[..., 2] << 16)
        lut = np.full((scene.ngeom + 2, 2), -1, dtype=np.int32)
        for geom in scene.geoms[: scene.ngeom]:
            if geom.segid != -1:
                lut[geom.segid + 1] = (geom.objid, geom.objtype)
        seg = lut[np.minimum(segid, scene.ngeom + 1)]
        if r._gl_context:  # EGL/OSMesa images are bottom-up
            depth = np.flipud(depth)
            seg = np.flipud(seg)
        return np.ascontiguousarray(depth), np.ascontiguousarray(seg)

    def close(self) -> None:
        """Free the renderer's GL resources."""
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None
        closed(self)
