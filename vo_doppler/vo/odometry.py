"""Streaming monocular visual odometry: KLT front end, essential-matrix initialisation, PnP
tracking, and Levenberg–Marquardt bundle adjustment over a sliding window of frames, solved at
every ``ba_every_keyframes``-th keyframe (a fixed lag) with the landmarks in a
:class:`~vo_doppler.vo.landmarks.LandmarkMap`.

World frame: the first camera's frame (OpenCV axes). Internally poses are world→camera (T_cw);
results are camera→world (T_wc). Without a metric source the translation unit is arbitrary
(the first initialisation baseline has length 1); :mod:`vo_doppler.vo.scale` makes it metric.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from dataclasses import dataclass, field

import cv2
import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.camera import Camera
from vo_doppler.model.visual_odometry import VoStats
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.geometry import (
    camera_center,
    invert_pose,
    project,
    solve_pnp,
    transform_points,
    triangulate,
    two_view_geometry,
)
from vo_doppler.vo.landmarks import LandmarkMap
from vo_doppler.vo.tracker import FeatureTracker, TrackedFeatures
from vo_doppler.vo.window_ba import BundleProblem, bundle_adjust

log = logging.getLogger(__name__)

MAX_CONSECUTIVE_FAILURES = 3
MIN_TRACKED = 30


@dataclass
class FrameResult:
    """What ``process`` returns for one image: the current camera→world pose estimate."""

    index: int
    t: float
    T_wc: np.ndarray
    n_tracks: int
    keyframe: bool
    flags: list[str]


@dataclass
class _Frame:
    index: int
    t: float
    T_cw: np.ndarray
    features: TrackedFeatures
    measured: bool
    """Pose comes from image geometry (not from a motion prediction)."""
    keyframe: bool = False
    flags: list[str] = field(default_factory=list)
    still_of: _Frame | None = None
    """The frame this one stood still at (a standstill or a duplicate image): its final pose is
    that frame's, whatever the window adjustment made of its own copy."""


RECENT_FRAMES = 5
"""Finished frames kept whole: the re-initialisation's scale looks at the last few."""


class _FinishedFrames:
    """The frames that left the window, whose poses no longer change, in arrays grown by
    doubling: time, world→camera pose, measured and keyframe flags, the flags of the frames
    that have some, and the last :data:`RECENT_FRAMES` frames whole. Holding every frame object
    instead grew the run's memory with the drive's duration several times faster (issue 30; the
    sizes per frame in docs/benchmarks.md, "Memory")."""

    def __init__(self) -> None:
        self.count = 0
        self.t = np.zeros(0)
        self.T_cw = np.zeros((0, 4, 4))
        self.measured = np.zeros(0, dtype=bool)
        self.keyframe = np.zeros(0, dtype=bool)
        self.flags: dict[int, list[str]] = {}
        self.recent: deque[_Frame] = deque(maxlen=RECENT_FRAMES)

    def add(self, frame: _Frame) -> None:
        """Record a frame whose pose is final: a frame that stood still takes the pose of the
        frame it stood still at (finished before it); one without a measured pose and without
        a reason is flagged 'no-geometry'."""
        if self.count == len(self.t):
            size = max(2 * self.count, 64)
            self.t = np.resize(self.t, size)
            self.T_cw = np.resize(self.T_cw, (size, 4, 4))
            self.measured = np.resize(self.measured, size)
            self.keyframe = np.resize(self.keyframe, size)
        if frame.still_of is not None:
            frame.T_cw = frame.still_of.T_cw.copy()
        if not frame.measured and not frame.flags:
            frame.flags.append("no-geometry")
        k = self.count
        self.t[k], self.T_cw[k] = frame.t, frame.T_cw
        self.measured[k], self.keyframe[k] = frame.measured, frame.keyframe
        if frame.flags:
            self.flags[k] = frame.flags
        self.recent.append(frame)
        self.count += 1


@dataclass
class VoResult:
    """Final (window-refined) camera→world poses, one per input image, and run statistics."""

    t: np.ndarray
    poses_wc: np.ndarray
    measured: np.ndarray
    stats: VoStats


class VisualOdometry:
    """Monocular VO over a stream of grey images: ``process(image, t)`` then ``finish()``."""

    def __init__(self, camera: Camera, config: VoConfig | None = None):
        self.camera = camera
        self.config = config or VoConfig()
        self.K = camera.K
        self.tracker = FeatureTracker(self.config)
        self._window: deque[_Frame] = deque()
        self._finished = _FinishedFrames()
        self._landmarks = LandmarkMap()
        self._initialised = False
        self._init_ref: _Frame | None = None
        self._ref_image: np.ndarray | None = None
        self._ref_frame: _Frame | None = None
        self._last_keyframe: _Frame | None = None
        self._keyframes_since_adjustment = 0
        self._failures = 0
        self._track_counts: list[int] = []
        self._rms_values: list[float] = []
        self._stats = VoStats()
        self._started = time.perf_counter()
        self._frames_seen = 0

    # -- public API ---------------------------------------------------------------------------

    def process(self, image: np.ndarray | None, t: float) -> FrameResult:
        """Estimate the pose of one image (``None`` = unreadable) taken at time ``t``."""
        index = self._frames_seen
        last = self._window[-1].t if self._window else None
        if not np.isfinite(t) or (last is not None and t <= last):
            raise InputError(f"frame {index}: time {t!r} is not after the previous frame's {last}")
        if image is not None:
            mismatch = self.camera.size_mismatch(image.shape[1], image.shape[0])
            if mismatch:
                raise InputError(f"frame {index}: {mismatch}")
        self._frames_seen += 1
        frame = _Frame(index, float(t), self._predict(), TrackedFeatures.empty(), False)
        problem = self._image_problem(image)
        if problem:
            frame.flags.append(problem)
            self._failures += 1
        elif self._ref_image is None:
            self._start(frame, image)
        else:
            self._track(frame, image)
        self._push(frame)
        self._track_counts.append(len(frame.features))
        return FrameResult(
            index,
            frame.t,
            invert_pose(frame.T_cw),
            len(frame.features),
            frame.keyframe,
            list(frame.flags),
        )

    def finish(self) -> VoResult:
        """Flush the window and return every frame's final pose and the run statistics."""
        done = self._finished
        while self._window:
            done.add(self._window.popleft())
        n = done.count
        stats = self._stats
        stats.frames = n
        stats.keyframes = int(done.keyframe[:n].sum())
        stats.wall_seconds = time.perf_counter() - self._started
        stats.mean_tracks = float(np.mean(self._track_counts)) if self._track_counts else 0.0
        stats.reprojection_rms_px = (
            float(np.sqrt(np.mean(np.square(self._rms_values))))
            if self._rms_values
            else float("nan")
        )
        stats.flagged_frames = [
            {"index": k, "t": float(done.t[k]), "reasons": reasons}
            for k, reasons in sorted(done.flags.items())
        ]
        return VoResult(
            done.t[:n].copy(), invert_pose(done.T_cw[:n]), done.measured[:n].copy(), stats
        )

    # -- stages -------------------------------------------------------------------------------

    def _image_problem(self, image: np.ndarray | None) -> str | None:
        if image is None:
            return "unreadable"
        if image.ndim != 2:
            return "not-grey"
        if float(cv2.meanStdDev(image)[1][0, 0]) < self.config.min_texture_std_grey:
            return "blank"
        if self._ref_image is not None and image.shape != self._ref_image.shape:
            return "size-changed"
        return None

    def _start(self, frame: _Frame, image: np.ndarray) -> None:
        frame.features = self.tracker.detect(image, TrackedFeatures.empty())
        frame.measured = True
        self._set_reference(frame, image)
        self._init_ref = frame
        if len(frame.features) < MIN_TRACKED:
            frame.flags.append("few-features")

    def _set_reference(self, frame: _Frame, image: np.ndarray) -> None:
        self._ref_image = image
        self._ref_frame = frame
        self._failures = 0

    def _track(self, frame: _Frame, image: np.ndarray) -> None:
        ref = self._ref_frame
        guess = self._predicted_positions(ref, frame) if ref.index < frame.index - 1 else None
        result = self.tracker.track(self._ref_image, image, ref.features, guess)
        if result.n_tracked < MIN_TRACKED:
            self._fail(frame, image, "tracking-lost")
            return
        frame.features = result.features
        if np.array_equal(image, self._ref_image):
            frame.flags.append("duplicate")
        if result.median_flow_px < self.config.standstill_flow_px:
            frame.T_cw = ref.T_cw.copy()
            frame.still_of = ref.still_of or ref
            frame.measured = ref.measured
            if "duplicate" not in frame.flags:
                frame.flags.append("standstill")
            frame.features = ref.features if "duplicate" in frame.flags else frame.features
            self._set_reference(frame, image)
            return
        if not self._initialised:
            self._try_initialise(frame)
            self._set_reference(frame, image)
            frame.features, _ = self.tracker.replenish(image, frame.features)
            return
        self._track_with_map(frame)
        if frame.measured:
            self._set_reference(frame, image)
            frame.features, _ = self.tracker.replenish(image, frame.features)
        else:
            self._fail(frame, image, "pnp-failed")

    def _predicted_positions(self, ref: _Frame, frame: _Frame) -> np.ndarray | None:
        """Where the reference features should appear in ``frame`` by the motion prediction:
        landmarks are projected; other features move by the landmarks' median displacement."""
        if not self._initialised or not len(ref.features):
            return None
        has_landmark, points = self._landmarks.lookup(ref.features.ids)
        if has_landmark.sum() < MIN_TRACKED:
            return None
        in_front = transform_points(frame.T_cw, points)[:, 2] > 0.1
        if in_front.sum() < MIN_TRACKED:
            return None
        projected = project(self.K, frame.T_cw, points[in_front])
        moved = ref.features.points[has_landmark][in_front]
        guess = ref.features.points + np.median(projected - moved, axis=0)
        rows = np.flatnonzero(has_landmark)[in_front]
        guess[rows] = projected
        return guess

    def _fail(self, frame: _Frame, image: np.ndarray, reason: str) -> None:
        frame.flags.append(reason)
        frame.measured = False
        self._failures += 1
        if self._failures >= MAX_CONSECUTIVE_FAILURES:
            log.warning(
                "frame %d: %s; %d frames in a row without a measured pose; re-initialising",
                frame.index,
                reason,
                self._failures,
            )
            frame.flags.append("reinitialised")
            frame.features = self.tracker.detect(image, TrackedFeatures.empty())
            self._landmarks.clear()
            self._initialised = False
            self._init_ref = frame
            self._set_reference(frame, image)

    def _try_initialise(self, frame: _Frame) -> None:
        cfg = self.config
        ref = self._init_ref
        ids, ia, ib = np.intersect1d(ref.features.ids, frame.features.ids, return_indices=True)
        frame.T_cw = ref.T_cw.copy()
        if len(ids) < cfg.init_min_points:
            self._init_ref = frame
            return
        two_view = two_view_geometry(
            self.K,
            ref.features.points[ia],
            frame.features.points[ib],
            cfg.ransac_threshold_px,
            cfg.max_reprojection_px,
            cfg.triangulation_min_parallax_rad,
        )
        if (
            two_view is None
            or two_view.median_parallax < cfg.init_min_parallax_rad
            or two_view.valid.sum() < cfg.init_min_points
        ):
            return
        scale = self._reinit_scale(ref, frame)
        T_ba = two_view.T_ba.copy()
        T_ba[:3, 3] *= scale
        frame.T_cw = T_ba @ ref.T_cw
        frame.measured = True
        T_wa = invert_pose(ref.T_cw)
        points_world = transform_points(T_wa, two_view.points_a[two_view.valid] * scale)
        self._landmarks.set(ids[two_view.valid], points_world)
        self._initialised = True
        self._stats.initialisations += 1
        self._relocate_pending(ref, frame)
        self._make_keyframe(frame)

    def _reinit_scale(self, ref: _Frame, frame: _Frame) -> float:
        """Map unit for a (re-)initialisation: 1 at start, else the recent speed × frame gap."""
        history = [f for f in list(self._finished.recent) + list(self._window) if f.measured]
        history = [f for f in history if f.index <= ref.index]
        if len(history) < 2:
            return 1.0
        a, b = history[-2], history[-1]
        step = np.linalg.norm(camera_center(a.T_cw) - camera_center(b.T_cw))
        per_frame = step / max(b.index - a.index, 1)
        return float(max(per_frame * (frame.index - ref.index), 1e-6)) if step > 0 else 1.0

    def _relocate_pending(self, ref: _Frame, frame: _Frame) -> None:
        """Frames between the initialisation pair get their pose by PnP on the new map."""
        for pending in self._window:
            if ref.index < pending.index < frame.index and len(pending.features):
                pnp = self._pnp(pending, pending.T_cw)
                if pnp is not None:
                    pending.T_cw = pnp
                    pending.measured = True

    def _pnp(self, frame: _Frame, guess: np.ndarray) -> np.ndarray | None:
        mask, points = self._landmarks.lookup(frame.features.ids)
        if mask.sum() < self.config.pnp_min_inliers:
            return None
        result = solve_pnp(
            self.K,
            points,
            frame.features.points[mask],
            guess,
            self.config.ransac_threshold_px * 2.0,
            self.config.pnp_min_inliers,
        )
        return None if result is None else result.T_cw

    def _track_with_map(self, frame: _Frame) -> None:
        pose = self._pnp(frame, frame.T_cw)
        if pose is None:
            return
        frame.T_cw = pose
        frame.measured = True
        if self._needs_keyframe(frame):
            self._make_keyframe(frame)

    def _needs_keyframe(self, frame: _Frame) -> bool:
        kf = self._last_keyframe
        if kf is None or frame.index - kf.index >= self.config.keyframe_max_gap:
            return True
        ids, ia, ib = np.intersect1d(kf.features.ids, frame.features.ids, return_indices=True)
        if len(ids) < 0.5 * len(kf.features):
            return True
        flow = np.linalg.norm(kf.features.points[ia] - frame.features.points[ib], axis=1)
        return bool(np.median(flow) > self.config.keyframe_flow_px)

    def _make_keyframe(self, frame: _Frame) -> None:
        frame.keyframe = True
        self._last_keyframe = frame
        self._triangulate_new(frame)
        self._keyframes_since_adjustment += 1
        if self._keyframes_since_adjustment >= self.config.ba_every_keyframes:
            self._adjust_window()

    def _triangulate_new(self, frame: _Frame) -> None:
        """New landmarks from tracks without one, using each track's oldest measured view."""
        cfg = self.config
        new = ~self._landmarks.contains(frame.features.ids)
        if not new.any():
            return
        wanted = frame.features.ids[new]
        for older in self._window:
            if not older.measured or older.index >= frame.index or not len(wanted):
                continue
            ids, ia, _ = np.intersect1d(older.features.ids, wanted, return_indices=True)
            if not len(ids):
                continue
            _, _, jb = np.intersect1d(ids, frame.features.ids, return_indices=True)
            tri = triangulate(
                self.K,
                older.T_cw,
                frame.T_cw,
                older.features.points[ia],
                frame.features.points[jb],
                cfg.max_reprojection_px,
                cfg.triangulation_min_parallax_rad,
            )
            self._landmarks.set(ids[tri.valid], tri.points[tri.valid])
            wanted = np.setdiff1d(wanted, ids)

    def _adjust_window(self) -> None:
        """Bundle adjustment of the window's measured frames and the landmarks they share."""
        frames = [f for f in self._window if f.measured]
        if len(frames) < 3:
            return
        self._keyframes_since_adjustment = 0
        landmarks = self._landmarks
        obs_f, obs_p, obs_uv = [], [], []
        for k, f in enumerate(frames):
            hit, rows = landmarks.rows(f.features.ids)
            obs_f.append(np.full(hit.sum(), k))
            obs_p.append(rows[hit])
            obs_uv.append(f.features.points[hit])
        obs_p_all = np.concatenate(obs_p)
        counts = np.bincount(obs_p_all, minlength=len(landmarks))
        used = np.flatnonzero(counts >= 2)
        remap = np.full(len(landmarks), -1)
        remap[used] = np.arange(len(used))
        keep = remap[obs_p_all] >= 0
        problem = BundleProblem(
            np.array([f.T_cw for f in frames]),
            landmarks.xyz[used],
            np.concatenate(obs_f)[keep],
            remap[obs_p_all[keep]],
            np.concatenate(obs_uv)[keep],
            n_fixed=min(self.config.ba_fixed_oldest, len(frames) - 1),
        )
        if len(problem.points) < 10:
            return
        result = bundle_adjust(
            self.K,
            problem,
            self.config.ba_max_iterations,
            self.config.ba_loss_scale_px,
            self.camera.width or 4000,
            self.camera.height or 4000,
            self.config.ba_function_tolerance,
            self.config.ba_threads,
        )
        self._stats.ba_runs += 1
        self._stats.ba_iterations += result.iterations
        if not result.converged or not np.all(np.isfinite(result.poses_cw)):
            log.warning("window bundle adjustment failed; keeping the previous estimate")
            return
        self._rms_values.append(result.final_rms_px)
        for f, pose in zip(frames, result.poses_cw, strict=True):
            f.T_cw = pose
        predicted = project(
            self.K, result.poses_cw[problem.obs_frame], result.points[problem.obs_point]
        )
        errors = np.linalg.norm(predicted - problem.obs_uv, axis=1)
        depth_ok = (
            transform_points(result.poses_cw[problem.obs_frame], result.points[problem.obs_point])[
                :, 2
            ]
            > 0
        )
        bad_obs = (errors > 2.0 * self.config.max_reprojection_px) | ~depth_ok
        landmarks.xyz[used] = result.points
        landmarks.remove(landmarks.ids[used[np.unique(problem.obs_point[bad_obs])]])

    # -- bookkeeping --------------------------------------------------------------------------

    def _predict(self) -> np.ndarray:
        """Constant-velocity prediction of the next world→camera pose."""
        recent = list(self._window)[-2:]
        if not recent:
            recent = self._finished.recent
            return recent[-1].T_cw.copy() if recent else np.eye(4)
        if len(recent) == 1:
            return recent[-1].T_cw.copy()
        prev, last = recent
        return last.T_cw @ invert_pose(prev.T_cw) @ last.T_cw

    def _push(self, frame: _Frame) -> None:
        self._window.append(frame)
        while len(self._window) > self.config.window_size:
            leaving = self._window.popleft()
            if all(
                leaving is not kept
                for kept in (self._ref_frame, self._init_ref, self._last_keyframe)
            ):
                leaving.features = TrackedFeatures.empty()
            self._finished.add(leaving)
        self._prune_landmarks()

    def _prune_landmarks(self) -> None:
        if len(self._landmarks) < 4 * self.config.max_features:
            return
        self._landmarks.retain(np.concatenate([f.features.ids for f in self._window]))
