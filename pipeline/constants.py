"""Names and numbers every stage agrees on (DESIGN.md): ramp directions, row statuses, vacuum."""

from __future__ import annotations

#: ramp directions in a manifest: increasing and decreasing pressure
DIRECTIONS: tuple[str, ...] = ("up", "down")
#: measurement status of a row: a trusted number, a doubtful number, no number
STATUSES: tuple[str, ...] = ("ok", "flagged", "failed")
#: rest bending angle psi0 of the paper's actuators (deg, DESIGN.md): the fallback where no material
#: says its own (a material's is ``Material.psi0_deg``, from the materials file)
PSI0_DEG: float = 210.0
#: absolute vacuum as a gauge pressure (kPa): no pneumatic pressure can be lower
VACUUM_KPA: float = -101.3
