"""The tracker's status per frame and the rules that move it (SPEC 6, 9; thesis §3.3, §3.4.9).

no_person --a face is found--> initialising --start-up check passes `confirm_frames`
frames in a row, or a fit from any pose explains the silhouette--> tracked
initialising --no face--> no_person
tracked --a hand is lost--> lost --every hand found again--> tracked
tracked / lost --the person is gone for `leave_frames`--> no_person
"""

from __future__ import annotations

from dataclasses import dataclass

from upperpose.result import INITIALISING, LOST, NO_PERSON, STATUSES, TRACKED


@dataclass
class StateMachine:
    """Counts the evidence of each frame and decides the status.

    Args:
        confirm_frames: consecutive frames the start-up check must pass before tracking starts.
        leave_frames: consecutive frames without the person before tracking stops.
    """

    confirm_frames: int = 3
    leave_frames: int = 8
    status: str = NO_PERSON
    _confirmed: int = 0
    _absent: int = 0

    @property
    def has_person(self) -> bool:
        """True while tracked or lost (the body model is in use)."""
        return self.status in (TRACKED, LOST)

    def startup(self, face_found: bool, passed: bool) -> bool:
        """Feeds one start-up frame (only while no person is tracked).

        Args:
            face_found: a frontal face was detected in this frame.
            passed: the start-up check (three skin blobs in the A-pose) passed.

        Returns:
            True when tracking should start with this frame (the check passed
            `confirm_frames` times in a row); the status is then TRACKED.
        """
        if self.has_person:
            raise RuntimeError("startup() is for frames without a tracked person")
        if not face_found:
            self.status, self._confirmed = NO_PERSON, 0
            return False
        if not passed:
            self.status, self._confirmed = INITIALISING, 0
            return False
        self._confirmed += 1
        if self._confirmed >= self.confirm_frames:
            self.status, self._confirmed, self._absent = TRACKED, 0, 0
            return True
        self.status = INITIALISING
        return False

    def start(self) -> None:
        """Tracking starts with this frame (a fit from any pose explained the silhouette)."""
        if self.has_person:
            raise RuntimeError("start() is for frames without a tracked person")
        self.status, self._confirmed, self._absent = TRACKED, 0, 0

    def tracking(self, present: bool, lost: bool) -> str:
        """Feeds one tracked frame: is the person still there, is any part lost.

        Returns:
            The new status (NO_PERSON once the person was absent `leave_frames` in a row).
        """
        if not self.has_person:
            raise RuntimeError("tracking() needs a tracked person")
        self._absent = 0 if present else self._absent + 1
        if self._absent >= self.leave_frames:
            self.reset()
        else:
            self.status = LOST if lost else TRACKED
        return self.status

    def reset(self) -> None:
        """Back to NO_PERSON (the person left, or the caller restarts)."""
        self.status, self._confirmed, self._absent = NO_PERSON, 0, 0


__all__ = ["INITIALISING", "LOST", "NO_PERSON", "STATUSES", "TRACKED", "StateMachine"]
