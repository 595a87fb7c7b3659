"""What the visual odometry gives back: its poses and the statistics of its run (the VO itself
is :mod:`vo_doppler.vo`; these are plain data, so a result can cross to a process that has not
loaded OpenCV or pycolmap, :mod:`vo_doppler.child_process`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from vo_doppler.model.trajectory import Trajectory


@dataclass
class VoStats:
    frames: int = 0
    keyframes: int = 0
    wall_seconds: float = 0.0
    mean_tracks: float = 0.0
    ba_runs: int = 0
    ba_iterations: int = 0
    reprojection_rms_px: float = float("nan")
    initialisations: int = 0
    flagged_frames: list[dict] = field(default_factory=list)

    @property
    def fps(self) -> float:
        return self.frames / self.wall_seconds if self.wall_seconds > 0 else float("nan")

    def to_dict(self) -> dict:
        return {
            "frames": self.frames,
            "keyframes": self.keyframes,
            "fps": self.fps,
            "wall_seconds": self.wall_seconds,
            "mean_tracks": self.mean_tracks,
            "ba_runs": self.ba_runs,
            "ba_iterations": self.ba_iterations,
            "reprojection_rms_px": self.reprojection_rms_px,
            "initialisations": self.initialisations,
            "flagged_frames": self.flagged_frames,
        }


@dataclass
class VoOutput:
    """Camera poses (camera→first-camera frame, OpenCV axes), one per image, and statistics."""

    trajectory: Trajectory
    stats: VoStats
    metric: bool
    """True when step lengths come from a speed signal; otherwise the unit is arbitrary."""
