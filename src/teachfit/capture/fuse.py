"""Fusing markers and cameras into one pose per part, and the relative pose G_T_L.

For one part and one frame (all cameras synchronised):

1. Hypotheses: every detected marker gives two ``part2rig`` poses (IPPE_SQUARE's pair),
   ``part2rig = cam2rig @ marker2cam @ inv(marker2part)``.
2. Selection: each hypothesis is scored by the truncated squared reprojection error of all the
   part's detected corners in all cameras, ``sum_m min(e_m^2, tau^2)`` with ``e_m`` a marker's
   RMS error (px) and ``tau = gate_px``; the lowest score wins. A lone marker (one camera)
   whose two solutions are within ``ambiguity_ratio`` of each other is resolved by the previous
   frame's pose when there is one.
3. Refinement on the markers within ``gate_px`` of the chosen pose, then outliers: markers
   whose RMS error under the refined pose exceeds ``outlier_px`` are dropped and the pose is
   refined again without them.
4. Refinement: Gauss-Newton with Huber weights on all inlier corners of all cameras,
   ``min sum_i rho(|u_i - pi_c(rig2cam_c (R X_i + t))|)``, with the left perturbation
   ``R <- exp([w]) R``, ``t <- exp([w]) t + v``. OpenCV has no multi-camera PnP for a rigid
   object with known extrinsics, hence this small solver; ``cv2.projectPoints`` supplies the
   projection with distortion and its Jacobian.
5. Quality: covariance of ``(w, v)`` (rad, m; rig frame) ``sigma^2 (J^T W J)^-1`` with
   ``sigma^2 = max(sum r^2 / (2N - 6), sigma_floor^2)``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.capture.detect import Detection, square_poses
from teachfit.capture.geometry import invert, rotation_angle_deg, skew
from teachfit.capture.markers import Marker
from teachfit.capture.rig import Rig
from teachfit.core.errors import CaptureError

__all__ = ["FusionConfig", "PartPose", "fuse_part", "relative_pose"]


@dataclass(frozen=True)
class FusionConfig:
    """Thresholds of the fusion (pixels) and of the solver."""

    outlier_px: float = 2.0
    gate_px: float = 10.0
    huber_px: float = 1.0
    sigma_floor_px: float = 0.15
    ambiguity_ratio: float = 1.5
    iterations: int = 10

    def __post_init__(self) -> None:
        if not (self.outlier_px > 0 and self.huber_px > 0 and self.sigma_floor_px > 0):
            raise CaptureError("outlier_px, huber_px and sigma_floor_px must be > 0")
        if self.gate_px < self.outlier_px:
            raise CaptureError("gate_px must be >= outlier_px")
        if self.ambiguity_ratio < 1 or self.iterations < 1:
            raise CaptureError("ambiguity_ratio must be >= 1 and iterations >= 1")


@dataclass(frozen=True, eq=False)
class PartPose:
    """A part's fused pose in the rig frame.

    Attributes
    ----------
    part2rig : (4, 4)
    cov : (6, 6) covariance of the left perturbation ``(w [rad], v [m])`` in the rig frame
    rms_px : RMS reprojection error of the inlier corners (px)
    markers : ids of the inlier markers; cameras : indices of the cameras that saw them
    rejected : ids of markers dropped as outliers
    """

    part2rig: np.ndarray
    cov: np.ndarray
    rms_px: float
    markers: tuple[int, ...]
    cameras: tuple[int, ...]
    rejected: tuple[int, ...]


def _project(rig: Rig, cam: int, X_rig: np.ndarray, jac: bool = False):
    c = rig.cameras[cam]
    X_c = X_rig @ c.rig2cam[:3, :3].T + c.rig2cam[:3, 3]
    uv, J = cv2.projectPoints(X_c.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), c.K, c.dist)
    return (
        (uv.reshape(-1, 2), J[:, 3:6].reshape(-1, 2, 3) @ c.rig2cam[:3, :3])
        if jac
        else uv.reshape(-1, 2)
    )


def _stack(dets: Sequence[Detection], markers: Mapping[int, Marker]):
    """Per camera: (part points (n, 3), image points (n, 2), owning marker ids (n,))."""
    groups: dict[int, list[Detection]] = {}
    for d in dets:
        groups.setdefault(d.camera, []).append(d)
    return {
        cam: (
            np.concatenate([markers[d.marker_id].corners_in_part for d in ds]),
            np.concatenate([d.corners for d in ds]),
            np.repeat([d.marker_id for d in ds], 4),
        )
        for cam, ds in groups.items()
    }


def _marker_rms(T: np.ndarray, rig: Rig, groups) -> dict[tuple[int, int], float]:
    out = {}
    for cam, (P, uv, ids) in groups.items():
        err = np.sum((_project(rig, cam, P @ T[:3, :3].T + T[:3, 3]) - uv) ** 2, axis=1)
        for m in np.unique(ids):
            out[(cam, int(m))] = float(np.sqrt(err[ids == m].mean()))
    return out


def _refine(T: np.ndarray, rig: Rig, groups, cfg: FusionConfig):
    """Huber-weighted Gauss-Newton on SE(3); returns (T, cov (6, 6), rms px)."""
    for _ in range(cfg.iterations):
        H, g, r2, n = np.zeros((6, 6)), np.zeros(6), 0.0, 0
        for cam, (P, uv, _ids) in groups.items():
            X = P @ T[:3, :3].T + T[:3, 3]
            proj, A = _project(rig, cam, X, jac=True)
            r = uv - proj  # (n, 2)
            J = np.concatenate([-A @ np.stack([skew(x) for x in X]), A], axis=2)  # (n, 2, 6)
            norm = np.linalg.norm(r, axis=1)
            w = np.where(norm <= cfg.huber_px, 1.0, cfg.huber_px / np.maximum(norm, 1e-12))
            H += np.einsum("n,nai,naj->ij", w, J, J)
            g += np.einsum("n,nai,na->i", w, J, r)
            r2 += float(np.sum(norm**2))
            n += len(P)
        try:
            delta = np.linalg.solve(H, g)
        except np.linalg.LinAlgError:
            return None
        dR = Rotation.from_rotvec(delta[:3]).as_matrix()
        T = T.copy()
        T[:3, :3] = dR @ T[:3, :3]
        T[:3, 3] = dR @ T[:3, 3] + delta[3:]
        if np.linalg.norm(delta[:3]) < 1e-9 and np.linalg.norm(delta[3:]) < 1e-9:
            break
    U, _, Vt = np.linalg.svd(T[:3, :3])  # re-orthonormalise after the updates
    T[:3, :3] = U @ Vt
    sigma2 = max(r2 / max(2 * n - 6, 1), cfg.sigma_floor_px**2)
    try:
        cov = sigma2 * np.linalg.inv(H)
    except np.linalg.LinAlgError:
        return None
    return T, cov, float(np.sqrt(r2 / max(n, 1)))


def fuse_part(
    dets: Sequence[Detection],
    rig: Rig,
    markers: Mapping[int, Marker],
    cfg: FusionConfig | None = None,
    prior: np.ndarray | None = None,
) -> PartPose | None:
    """Pose of the part carrying ``dets``' markers, or None when nothing trustworthy is seen.

    Parameters
    ----------
    dets : detections of this part's markers, from any cameras
    markers : id -> marker (the part's markers)
    prior : (4, 4) ``part2rig`` of the previous frame, used to break a lone marker's ambiguity
    """
    cfg = cfg or FusionConfig()
    dets = [d for d in dets if d.marker_id in markers]
    if not dets:
        return None
    hyps = _hypotheses(dets, rig, markers)
    if not hyps:
        return None
    groups = _stack(dets, markers)
    best = _best_hypothesis(hyps, len(dets), rig, groups, cfg, prior)
    # a single marker's pose is imprecise, so the first refinement takes every marker within
    # the loose gate; the final one only those within outlier_px of the refined pose
    rms = _marker_rms(hyps[best][0], rig, groups)
    keep = [d for d in dets if rms[(d.camera, d.marker_id)] <= cfg.gate_px]
    refined = _refine(hyps[best][0], rig, _stack(keep, markers), cfg)
    if refined is None:
        return None
    T, cov, err = refined
    rms = _marker_rms(T, rig, groups)
    inliers = [d for d in dets if rms[(d.camera, d.marker_id)] <= cfg.outlier_px]
    if not inliers:
        return None
    if len(inliers) != len(keep):
        refined = _refine(T, rig, _stack(inliers, markers), cfg)
        if refined is None:
            return None
        T, cov, err = refined
    used = {d.marker_id for d in inliers}
    return PartPose(
        part2rig=T,
        cov=cov,
        rms_px=err,
        markers=tuple(sorted(used)),
        cameras=tuple(sorted({d.camera for d in inliers})),
        rejected=tuple(sorted({d.marker_id for d in dets} - used)),
    )


def _hypotheses(
    dets: Sequence[Detection], rig: Rig, markers: Mapping[int, Marker]
) -> list[tuple[np.ndarray, float]]:
    """Every candidate ``part2rig`` (4, 4) of the single-marker poses of ``dets`` (both IPPE
    solutions each), with its reprojection error (px)."""
    hyps = []
    for d in dets:
        cam, m = rig.cameras[d.camera], markers[d.marker_id]
        for marker2cam, err in square_poses(d.corners, m.size, cam.K, cam.dist):
            hyps.append((cam.cam2rig @ marker2cam @ invert(m.marker2part), err))
    return hyps


def _best_hypothesis(
    hyps: Sequence[tuple[np.ndarray, float]],
    n_dets: int,
    rig: Rig,
    groups: dict,
    cfg: FusionConfig,
    prior: np.ndarray | None,
) -> int:
    """Index of the hypothesis that explains all detections best (robust score: squared RMS
    per marker, capped at the gate); a lone marker's two nearly equal solutions are decided
    by the rotation closer to ``prior`` (4, 4)."""
    tau2 = cfg.gate_px**2
    scores = [sum(min(e * e, tau2) for e in _marker_rms(T, rig, groups).values()) for T, _ in hyps]
    best = int(np.argmin(scores))
    if n_dets == 1 and len(hyps) == 2 and prior is not None:
        e0, e1 = sorted(e for _, e in hyps)
        if e1 < cfg.ambiguity_ratio * max(e0, 1e-3):
            gaps = [rotation_angle_deg(prior[:3, :3].T @ T[:3, :3]) for T, _ in hyps]
            best = int(np.argmin(gaps))
    return best


def relative_pose(ref: PartPose, moving: PartPose) -> tuple[np.ndarray, np.ndarray]:
    """``L2G = inv(G2rig) @ L2rig`` and its covariance (6, 6) ``(rotation rad, position m)``
    expressed in ``G``, by first-order propagation of both parts' covariances:
    ``d_theta = R_G^T (w_L - w_G)``,
    ``d_p = R_G^T (-[t_L]x (w_L - w_G) + v_L - v_G)``."""
    G, L = ref.part2rig, moving.part2rig
    RGt, S = G[:3, :3].T, skew(L[:3, 3])
    Z = np.zeros((3, 3))
    J = np.block([[RGt, Z, -RGt, Z], [-RGt @ S, RGt, RGt @ S, -RGt]])
    cov = J @ np.block([[moving.cov, np.zeros((6, 6))], [np.zeros((6, 6)), ref.cov]]) @ J.T
    return invert(G) @ L, cov
