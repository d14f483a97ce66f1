"""Demonstrations captured from video: multi-camera ArUco tracking of the parts.

The capture of Wang et al. 2019 (docs/methods.md).

A person assembles parts that carry square markers while calibrated cameras film; the tracker
turns the videos into the relative pose sequence ``L2G`` (the paper's G_T_L) that the planner
consumes. Modules, in data-flow order:

- :mod:`.rig`, :mod:`.markers`: the rig file (intrinsics, distortion, ``cam2rig``) and the
  marker file (dictionary, ids, sizes, ``marker2part``); :mod:`.calibrate`: ChArUco.
- :mod:`.sources`: synchronised, checked frames from videos or live cameras.
- :mod:`.detect`: ArUco detection, edge-based corner refinement, IPPE_SQUARE poses.
- :mod:`.fuse`: per-part fusion over markers and cameras, outliers, covariance, ``L2G``.
- :mod:`.temporal`: alpha-beta filter with gating; :mod:`.track`: the per-frame pipeline and
  the :class:`~teachfit.capture.track.Track` -> demonstration.
- :mod:`.scene`, :mod:`.synth`, :mod:`.synth_calib`: MuJoCo-rendered ground truth.
"""

from teachfit.capture.fuse import FusionConfig, PartPose, fuse_part, relative_pose
from teachfit.capture.markers import Marker, MarkerSet, read_markers, write_markers
from teachfit.capture.rig import Camera, Rig, read_rig, write_rig
from teachfit.capture.sources import CameraSet, VideoSet
from teachfit.capture.temporal import FilterConfig, PoseFilter
from teachfit.capture.track import STATUS, Track, TrackConfig, Tracker, track_frames

__all__ = [
    "STATUS",
    "Camera",
    "CameraSet",
    "FilterConfig",
    "FusionConfig",
    "Marker",
    "MarkerSet",
    "PartPose",
    "PoseFilter",
    "Rig",
    "Track",
    "TrackConfig",
    "Tracker",
    "VideoSet",
    "fuse_part",
    "read_markers",
    "read_rig",
    "relative_pose",
    "track_frames",
    "write_markers",
    "write_rig",
]
