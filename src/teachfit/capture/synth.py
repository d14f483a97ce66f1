"""Synthetic ground truth: a scripted L-into-groove demonstration rendered from several cameras.

The moving part carries a marker cube on a short stem (five markers, like the printed cubes used
in practice), the fixed part sits on a plate with markers near its corners. The parts follow
:func:`teachfit.plans.synth.synth_demo` (``L2G`` at 30 Hz) with ``G`` fixed in the rig (world)
frame; each camera looks at the assembly from ``distance`` m. Optional image effects: additive
Gaussian noise (grey levels), Gaussian blur (px) and a slowly varying key light.

Outputs of :func:`write_synth_capture`: ``cam<i>.mp4``, ``rig.toml``, ``markers.toml`` and
``truth.h5`` (the true ``L2G`` sequence as a demonstration, one sample per video frame).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field, replace
from pathlib import Path

import cv2
import imageio.v2 as imageio
import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.capture.markers import Marker, MarkerSet, marker_image, write_markers
from teachfit.capture.rig import Camera, Rig, write_rig
from teachfit.capture.scene import Carrier, Quad, camera_K, look_at, scene_xml
from teachfit.core.atomic import atomic_path
from teachfit.core.errors import CaptureError, RenderError
from teachfit.core.geometry import rotation_to_wxyz, wxyz_to_rotation
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.plans.synth import synth_demo
from teachfit.tasks.parts import Assembly, pose_from_xyz_rpy
from teachfit.tasks.registry import build_assembly

__all__ = [
    "SynthConfig",
    "SynthScene",
    "marker_layout",
    "synth_rig",
    "write_synth_capture",
]

DICTIONARY = "DICT_4X4_50"
CUBE = 0.030  # m, edge of the moving part's marker cube
STEM = 0.010  # m, gap between the part's top and the cube
CUBE_MARKER = 0.022  # m
PLATE_MARKER = 0.030  # m
LIFT = 2e-4  # m, markers stand this far off their carrier faces (no z-fighting)


@dataclass(frozen=True)
class SynthConfig:
    """Rendering set-up of a synthetic capture.

    Attributes
    ----------
    resolutions : sequence of (width, height) px, one per camera (its length = camera count)
    distance : m, from each camera to the assembly's centre
    elevation : deg, of the cameras above the table plane
    fovy : deg, vertical field of view
    noise : standard deviation (grey levels, 0-255) of additive Gaussian pixel noise
    blur : standard deviation (px) of a Gaussian blur; 0 for none
    lighting : relative amplitude of the key light's slow intensity variation, in [0, 1)
    stride : keep every ``stride``-th sample of the 30 Hz demonstration (video at 30/stride fps)
    max_frames : cap on the number of frames (None: the whole demonstration)
    crf : x264 constant rate factor of the videos (lower = better quality)
    """

    resolutions: tuple[tuple[int, int], ...] = ((1920, 1080), (1280, 720), (1920, 1080))
    distance: float = 0.6
    elevation: float = 45.0
    fovy: float = 36.0
    noise: float = 0.0
    blur: float = 0.0
    lighting: float = 0.0
    stride: int = 1
    max_frames: int | None = None
    crf: int = 18
    azimuths: tuple[float, ...] = field(default=(-30.0, 90.0, 210.0))

    def __post_init__(self) -> None:
        res = tuple((int(w), int(h)) for w, h in self.resolutions)
        if not res or any(w < 16 or h < 16 for w, h in res):
            raise CaptureError(f"need at least one camera of at least 16x16 px, got {res}")
        if len(res) > len(self.azimuths):
            raise CaptureError(f"at most {len(self.azimuths)} cameras (one per azimuth)")
        if not (self.distance > 0 and 0 < self.fovy < 170 and 0 < self.elevation < 90):
            raise CaptureError("distance must be > 0 m, fovy in (0, 170), elevation in (0, 90)")
        if self.noise < 0 or self.blur < 0 or not 0 <= self.lighting < 1 or self.stride < 1:
            raise CaptureError("noise, blur >= 0, lighting in [0, 1), stride >= 1 required")
        object.__setattr__(self, "resolutions", res)


def marker_layout(asm: Assembly) -> tuple[MarkerSet, dict[str, list[Carrier]]]:
    """Markers and their carriers for ``asm``: a cube on the moving part's highest point
    (ids 0-4: top, +x, -x, +y, -y faces) and a plate under the fixed part (ids 10-15)."""
    v = np.asarray(asm.moving.vertices)
    top = v[:, 2].max()
    xy = v[v[:, 2] > top - 1e-3, :2].mean(axis=0)
    c = np.array([xy[0], xy[1], top + STEM + CUBE / 2])
    h = CUBE / 2
    faces = {  # normal -> (rotation of marker2part)
        (0, 0, 1): [0, 0, 0],
        (1, 0, 0): [90, 0, 90],
        (-1, 0, 0): [90, 0, -90],
        (0, 1, 0): [-90, 180, 0],
        (0, -1, 0): [90, 0, 0],
    }
    markers = []
    for i, (n, rpy) in enumerate(faces.items()):
        T = pose_from_xyz_rpy(c + (h + LIFT) * np.array(n, dtype=float), rpy)
        if not np.allclose(T[:3, 2], n):
            raise AssertionError(f"marker normal {T[:3, 2]} != {n}")  # layout self-check
        markers.append(Marker(i, "L", CUBE_MARKER, T))
    carriers = {
        "L": [
            Carrier(tuple(c), (h, h, h)),
            Carrier((c[0], c[1], top + STEM / 2), (0.003, 0.003, STEM / 2 + 1e-3)),
        ]
    }
    lo, hi = np.asarray(asm.fixed.bounds)
    margin = 0.05
    plo, phi = lo[:2] - margin, hi[:2] + margin
    z = lo[2] - 0.004
    carriers["G"] = [
        Carrier(
            ((plo[0] + phi[0]) / 2, (plo[1] + phi[1]) / 2, z - 0.004),
            ((phi[0] - plo[0]) / 2, (phi[1] - plo[1]) / 2, 0.004),
            (0.8, 0.74, 0.62, 1.0),
        )
    ]
    inset = 0.6 * PLATE_MARKER + 0.004
    xs = (plo[0] + inset, 0.0, phi[0] - inset)
    for k, (x, y) in enumerate([(x, y) for y in (plo[1] + inset, phi[1] - inset) for x in xs]):
        T = pose_from_xyz_rpy(np.array([x, y, z + LIFT]), [0, 0, 0])
        markers.append(Marker(10 + k, "G", PLATE_MARKER, T))
    return MarkerSet(DICTIONARY, tuple(markers), reference="G", moving="L"), carriers


def synth_rig(cfg: SynthConfig, target: np.ndarray) -> Rig:
    """Cameras on a circle around ``target`` (rig = world frame), as a calibrated rig."""
    cams = []
    el = np.radians(cfg.elevation)
    for i, (w, h) in enumerate(cfg.resolutions):
        az = np.radians(cfg.azimuths[i])
        eye = target + cfg.distance * np.array(
            [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]
        )
        cams.append(
            Camera(f"cam{i}", w, h, camera_K(w, h, cfg.fovy), np.zeros(5), look_at(eye, target))
        )
    return Rig(tuple(cams))


class SynthScene:
    """A MuJoCo capture scene of a task's parts; :meth:`render` draws all cameras at a pose.

    Raises
    ------
    RenderError
        No OpenGL context (set ``MUJOCO_GL=egl`` or ``osmesa`` on a headless machine).
    """

    def __init__(self, asm: Assembly, cfg: SynthConfig, G2world: np.ndarray | None = None):
        self.asm, self.cfg = asm, cfg
        self.markers, carriers = marker_layout(asm)
        self.G2world = np.eye(4) if G2world is None else np.asarray(G2world, dtype=float)
        target = self.G2world[:3, :3] @ np.asarray(asm.fixed.bounds).mean(axis=0)
        self.rig = synth_rig(cfg, target + self.G2world[:3, 3])
        quads: dict[str, list[Quad]] = {"L": [], "G": []}
        for m in self.markers.markers:
            margin = (CUBE - CUBE_MARKER) / 2 / CUBE_MARKER if m.part == "L" else 0.25
            img = marker_image(self.markers.dictionary, m.id, 240, margin)
            side = m.size * img.shape[0] / 240  # the quiet zone is a whole number of pixels
            quads[m.part].append(Quad(f"m{m.id}", (side, side), m.marker2part, img))
        parts = {"G": (asm.fixed, (0.55, 0.57, 0.62, 1.0)), "L": (asm.moving, (0.9, 0.5, 0.15, 1))}
        cams = [(c.name, c.cam2rig, cfg.fovy) for c in self.rig.cameras]
        size = (max(w for w, _ in cfg.resolutions), max(h for _, h in cfg.resolutions))
        xml, assets = scene_xml(parts, carriers, quads, cams, offscreen=size)
        self.model = mujoco.MjModel.from_xml_string(xml, assets)
        self.data = mujoco.MjData(self.model)
        self._light0 = self.model.light_diffuse.copy()
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        for w, h in set(cfg.resolutions):
            try:
                self._renderers[(w, h)] = mujoco.Renderer(self.model, height=h, width=w)
            except Exception as exc:  # noqa: BLE001 - GL back-ends raise many unrelated types
                self.close()
                raise RenderError(
                    f"offscreen rendering is unavailable: {exc}. On a headless machine set "
                    "MUJOCO_GL=egl (Mesa's EGL works without a GPU) or MUJOCO_GL=osmesa."
                ) from exc

    def close(self) -> None:
        """Free the GL renderers."""
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()

    def _set_body(self, name: str, T: np.ndarray) -> None:
        mocap = int(self.model.body_mocapid[self.model.body(name).id])
        self.data.mocap_pos[mocap] = T[:3, 3]
        self.data.mocap_quat[mocap] = rotation_to_wxyz(
            Rotation.from_matrix(T[:3, :3]), canonical=False
        )

    def render(self, L2G: np.ndarray, rng: np.random.Generator, phase: float = 0.0) -> list:
        """RGB images (H, W, 3) uint8 of every camera with the moving part at ``L2G`` (4, 4).

        ``phase`` (rad) drives the lighting variation; ``rng`` the pixel noise.
        """
        self._set_body("G", self.G2world)
        self._set_body("L", self.G2world @ L2G)
        self.model.light_diffuse[:] = self._light0 * (1.0 + self.cfg.lighting * np.sin(phase))
        mujoco.mj_forward(self.model, self.data)
        images = []
        for i, (w, h) in enumerate(self.cfg.resolutions):
            r = self._renderers[(w, h)]
            r.update_scene(self.data, camera=f"cam{i}")
            img = r.render()
            if self.cfg.blur > 0:
                img = cv2.GaussianBlur(img, (0, 0), self.cfg.blur)
            if self.cfg.noise > 0:
                noisy = img + rng.normal(0.0, self.cfg.noise, img.shape)
                img = np.clip(noisy, 0, 255).astype(np.uint8)
            images.append(img)
        return images


def truth_demo(asm: Assembly, seed: int, cfg: SynthConfig) -> Demonstration:
    """The scripted ``L2G`` demonstration at the video's frame times (30 / stride Hz)."""
    demo = synth_demo(asm, seed, rate_hz=30.0)
    idx = np.arange(0, demo.n_samples, cfg.stride)[: cfg.max_frames]
    if len(idx) < 2:
        raise CaptureError("the synthetic capture needs at least 2 frames")
    return replace(
        demo,
        t=demo.t[idx],
        pos=demo.pos[idx],
        quat=demo.quat[idx],
        source="synthetic",
        name=f"{asm.task}-capture-truth-{seed}",
    )


def _matrices(demo: Demonstration) -> Iterator[np.ndarray]:
    rot = wxyz_to_rotation(demo.quat).as_matrix()
    for R, p in zip(rot, demo.pos, strict=True):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, p
        yield T


def write_synth_capture(
    out: str | Path,
    *,
    task: str = "l-groove",
    seed: int = 0,
    cfg: SynthConfig | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Path]:
    """Render a scripted demonstration to videos and write rig, markers and truth to ``out``.

    Returns the written paths: ``video0``, ``video1``, ..., ``rig``, ``markers``, ``truth``.
    ``progress(done, total)`` is called after each frame.
    """
    cfg = cfg or SynthConfig()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    asm = build_assembly(task)
    truth = truth_demo(asm, seed, cfg)
    G2world = pose_from_xyz_rpy(np.zeros(3), [0.0, 0.0, 15.0])
    scene = SynthScene(asm, cfg, G2world)
    fps = 30.0 / cfg.stride
    rng = np.random.default_rng(seed)
    paths = {f"video{i}": out / f"cam{i}.mp4" for i in range(len(cfg.resolutions))}
    try:
        with ExitStack() as files:
            writers = []
            for p in paths.values():
                tmp = files.enter_context(atomic_path(p, "video"))
                writer = imageio.get_writer(
                    tmp,
                    fps=fps,
                    codec="libx264",
                    quality=None,
                    macro_block_size=1,
                    ffmpeg_params=["-crf", str(cfg.crf), "-preset", "veryfast"],
                    ffmpeg_log_level="error",
                )
                files.callback(writer.close)  # closed before its file is moved into place
                writers.append(writer)
            for k, L2G in enumerate(_matrices(truth)):
                phase = 2 * np.pi * truth.t[k] / 3.0
                for writer, img in zip(writers, scene.render(L2G, rng, phase), strict=True):
                    writer.append_data(img)
                if progress is not None:
                    progress(k + 1, truth.n_samples)
    finally:
        scene.close()
    paths["rig"] = write_rig(scene.rig, out / "rig.toml")
    paths["markers"] = write_markers(scene.markers, out / "markers.toml")
    paths["truth"] = write_dataset(out / "truth.h5", [truth], overwrite=True)
    return paths
