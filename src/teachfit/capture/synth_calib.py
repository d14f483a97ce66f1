"""Synthetic ChArUco calibration shots: a board rendered in MuJoCo from the synthetic rig.

The board lies roughly flat in front of the cameras (random tilt up to ``tilt`` degrees, random
yaw, random offset); every shot is rendered by every camera and written as
``<out>/cam<i>/<shot>.png``, so :func:`teachfit.capture.calibrate.calibrate_folder` can
recover the rig, and the true rig is returned for comparison.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.capture.calibrate import CharucoSpec
from teachfit.capture.rig import Rig
from teachfit.capture.scene import Quad, scene_xml
from teachfit.capture.synth import SynthConfig, synth_rig
from teachfit.core.atomic import atomic_write_bytes
from teachfit.core.errors import RenderError
from teachfit.core.geometry import rotation_to_wxyz
from teachfit.tasks.parts import pose_from_xyz_rpy

__all__ = ["write_charuco_shots"]


def write_charuco_shots(
    out: str | Path,
    spec: CharucoSpec,
    cfg: SynthConfig,
    *,
    shots: int = 12,
    tilt: float = 40.0,
    seed: int = 0,
) -> Rig:
    """Render ``shots`` board poses from every camera of ``synth_rig(cfg)``; return the rig."""
    out = Path(out)
    rng = np.random.default_rng(seed)
    target = np.zeros(3)
    rig = synth_rig(cfg, target)
    sx, sy = spec.squares
    size = (sx * spec.square, sy * spec.square)
    px = 100  # texture pixels per square
    board_img = spec.board().generateImage((sx * px, sy * px), marginSize=0)
    # a white surround (0.2 mm below the board) gives the outer squares their quiet zone
    surround = (size[0] + 2 * spec.square, size[1] + 2 * spec.square)
    centre = np.array([size[0] / 2, size[1] / 2, 0.0])
    quads = [
        Quad("charuco", size, pose_from_xyz_rpy(centre, [0, 0, 0]), board_img),
        Quad(
            "surround",
            surround,
            pose_from_xyz_rpy(centre - [0, 0, 2e-4], [0, 0, 0]),
            np.full((8, 8), 255, np.uint8),
        ),
    ]
    cams = [(c.name, c.cam2rig, cfg.fovy) for c in rig.cameras]
    wmax, hmax = max(w for w, _ in cfg.resolutions), max(h for _, h in cfg.resolutions)
    xml, assets = scene_xml(
        {"B": (None, (1, 1, 1, 1))}, {}, {"B": quads}, cams, offscreen=(wmax, hmax)
    )
    model = mujoco.MjModel.from_xml_string(xml, assets)
    data = mujoco.MjData(model)
    try:
        renderers = [mujoco.Renderer(model, height=h, width=w) for w, h in cfg.resolutions]
    except Exception as exc:  # noqa: BLE001 - GL back-ends raise many unrelated types
        raise RenderError(f"offscreen rendering is unavailable ({exc}); set MUJOCO_GL=egl") from exc
    try:
        for k in range(shots):
            rpy = [rng.uniform(-tilt, tilt), rng.uniform(-tilt, tilt), rng.uniform(-180, 180)]
            centre = np.array([*rng.uniform(-0.04, 0.04, 2), rng.uniform(-0.05, 0.2)])
            T = pose_from_xyz_rpy(centre, rpy)
            T[:3, 3] -= T[:3, :3] @ np.array([size[0] / 2, size[1] / 2, 0.0])  # board centred
            data.mocap_pos[0] = T[:3, 3]
            data.mocap_quat[0] = rotation_to_wxyz(Rotation.from_matrix(T[:3, :3]), canonical=False)
            mujoco.mj_forward(model, data)
            for i, r in enumerate(renderers):
                r.update_scene(data, camera=f"cam{i}")
                ok, png = cv2.imencode(".png", cv2.cvtColor(r.render(), cv2.COLOR_RGB2GRAY))
                if not ok:
                    raise RenderError(f"cannot encode calibration image {k} of camera {i}")
                atomic_write_bytes(out / f"cam{i}" / f"{k:03d}.png", png.tobytes(), "image")
    finally:
        for r in renderers:
            r.close()
    return rig
