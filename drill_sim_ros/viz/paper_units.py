"""The paper's dimensionless variables (RGD07 eqs. 19-24) for the 2D views.

Telemetry is SI. The phase portrait (Fig. 5), the bottom-hole pattern (Fig. 7) and the
E-S diagram (Fig. 12, eqs. 48-50) are drawn in the paper's variables, which needs the
run's scales (t*, L*, force and torque units) and beta: they come from a model preset.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from drill_sim_ros.model.analysis import trivial_solution
from drill_sim_ros.model.params import RPM_PER_RAD_S, DimensionlessParams, Scales
from drill_sim_ros.model.presets import Preset, load_preset


@dataclass(frozen=True)
class PaperUnits:
    """Scales to dimensionless form plus the reference (trivial, eq. 34) motion.

    v0, omega0, delta0, w0, t0: trivial ROP, bit speed, depth of cut, WOB and TOB
    (dimensionless); beta: slope of the friction line (eq. 50); n: number of blades.
    """

    preset: str
    scales: Scales
    beta: float
    n: int
    v0: float
    omega0: float
    delta0: float
    w0: float
    t0: float

    @classmethod
    def from_preset(cls, preset: Preset) -> PaperUnits:
        triv = trivial_solution(preset.params)
        return cls(preset=preset.name, scales=preset.scales, beta=preset.params.beta,
                   n=preset.params.n, v0=triv.v, omega0=triv.omega,
                   delta0=triv.depth_of_cut, w0=triv.wob, t0=triv.torque)

    @classmethod
    def load(cls, name: str) -> PaperUnits:
        return cls.from_preset(load_preset(name))

    @classmethod
    def from_run_info(cls, info: dict[str, Any]) -> PaperUnits:
        """From what sim_node publishes on /drill/run_info: the groups and the scales."""
        groups = dict(info["groups"])
        params = DimensionlessParams(**{**groups, "n": int(groups["n"])})
        scales = Scales(time_s=float(info["t_star_s"]), length_m=float(info["l_star_m"]),
                        force_n=float(info["force_unit_n"]),
                        torque_nm=float(info["torque_unit_nm"]))
        triv = trivial_solution(params)
        return cls(preset=str(info.get("preset", "")), scales=scales, beta=params.beta,
                   n=params.n, v0=triv.v, omega0=triv.omega, delta0=triv.depth_of_cut,
                   w0=triv.wob, t0=triv.torque)

    def omega(self, rpm: np.ndarray) -> np.ndarray:
        """Bit speed rpm -> omega = Omega t* (eq. 21)."""
        return rpm / RPM_PER_RAD_S * self.scales.time_s

    def velocity(self, rop_m_s: np.ndarray) -> np.ndarray:
        """ROP m/s -> v = V t* / L*."""
        return rop_m_s * self.scales.time_s / self.scales.length_m

    def depth_of_cut(self, doc_m: np.ndarray) -> np.ndarray:
        """Depth of cut per revolution m -> delta = d / L*."""
        return doc_m / self.scales.length_m

    def weight(self, wob_n: np.ndarray) -> np.ndarray:
        """WOB N -> W = W / (zeta eps a L*) (eq. 20)."""
        return wob_n / self.scales.force_n

    def torque(self, tob_nm: np.ndarray) -> np.ndarray:
        """TOB N m -> T = T / C (eq. 20)."""
        return tob_nm / self.scales.torque_nm

    def friction_line(self, strength: np.ndarray) -> np.ndarray:
        """E = (1 - beta) + beta S (eq. 50)."""
        return (1.0 - self.beta) + self.beta * strength
