"""Names and numbers every stage agrees on (DESIGN.md): ramp directions, row statuses, vacuum."""

from __future__ import annotations

#: ramp directions in a manifest: increasing and decreasing pressure
DIRECTIONS: tuple[str, ...] = ("up", "down")
#: measurement status of a row: a trusted number, a doubtful number, no number
STATUSES: tuple[str, ...] = ("ok", "flagged", "failed")
#: absolute vacuum as a gauge pressure (kPa): no pneumatic pressure can be lower
VACUUM_KPA: float = -101.3
