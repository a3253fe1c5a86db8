"""The simulation as the node sees it: SI setpoints in, one SI telemetry row per period out.

ROS-free. A :class:`SimSession` owns the :class:`Simulator`, refines its step so a whole
number of steps fills one publish period, stamps samples with an integer-nanosecond
simulated clock that never goes back (not even on reset), and keeps a window of recent bit
speeds for the stick-slip severity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.analysis import Severity, severity
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.ros.conversions import NS_PER_S, TelemetryConverter


@dataclass(frozen=True)
class SessionConfig:
    """What the node's parameters fix for the lifetime of a session (SI units)."""

    preset: Preset
    publish_rate_hz: float = 100.0
    dtau_max: float = 1e-4
    n_nodes: int = 2048
    perturb_v: float = 0.0
    applied_wob_n: float | None = None
    surface_rpm: float | None = None
    top_drive_accel_rpm_s: float = 0.0   # 0: no limit
    wob_rate_n_s: float = 0.0            # 0: no limit
    window_s: float = 20.0


def period_ns(publish_rate_hz: float) -> int:
    """One publish period of simulated time in whole nanoseconds."""
    return round(NS_PER_S / publish_rate_hz)


def steps_per_period(period_tau: float, dtau_max: float) -> int:
    """The fewest whole steps of at most ``dtau_max`` that fill ``period_tau``."""
    return max(1, math.ceil(period_tau / dtau_max * (1.0 - 1e-12)))


def build_simulator(cfg: SessionConfig, period_tau: float, steps: int) -> Simulator:
    """The simulator of ``cfg`` with initial setpoints and ramp limits in model units."""
    sc = cfg.preset.scales
    params = cfg.preset.params
    if cfg.applied_wob_n is not None:
        params = params.with_(w0=sc.w_from_newton(cfg.applied_wob_n))
    if cfg.surface_rpm is not None:
        params = params.with_(omega0=sc.omega_from_rpm(cfg.surface_rpm))
    omega_rate = (sc.omega_from_rpm(cfg.top_drive_accel_rpm_s) * sc.time_s
                  if cfg.top_drive_accel_rpm_s > 0 else math.inf)
    w_rate = sc.w_from_newton(cfg.wob_rate_n_s) * sc.time_s if cfg.wob_rate_n_s > 0 else math.inf
    config = SimConfig(dtau=period_tau / steps, n_nodes=cfg.n_nodes, omega_rate=omega_rate,
                       w_rate=w_rate)
    return Simulator(params, config, perturb_v=cfg.perturb_v)


class SimSession:
    """Advances whole publish periods and returns SI telemetry rows."""

    def __init__(self, cfg: SessionConfig) -> None:
        self.cfg = cfg
        self.scales = cfg.preset.scales
        self.period_ns = period_ns(cfg.publish_rate_hz)
        period_tau = self.period_ns / NS_PER_S / self.scales.time_s
        self.steps = steps_per_period(period_tau, cfg.dtau_max)
        self.sim = build_simulator(cfg, period_tau, self.steps)
        self.sim.advance(0)          # load the compiled kernel now, not on the first tick
        self.next_index = 0          # sample counter: stamps = index * period_ns
        self._converter = TelemetryConverter(self.scales)
        size = max(2, round(cfg.window_s * cfg.publish_rate_hz))
        self._omega = [0.0] * size       # ring buffers of the recent window
        self._stuck = [False] * size
        self._head = 0                   # where the next sample goes
        self._filled = 0

    @property
    def dtau(self) -> float:
        return self.sim.config.dtau

    @property
    def sim_time_ns(self) -> int:
        """Stamp of the next sample (the simulated clock)."""
        return self.next_index * self.period_ns

    def run(self, periods: int, submerged_weight_n: float) -> tuple[list[int], list[list[float]]]:
        """Advance ``periods`` publish periods: (stamps ns, SI rows of ``TELEMETRY_FIELDS``).

        Row i is the state at the start of period i. Raises ``NumericalFault``.
        """
        samples = self.sim.advance(periods * self.steps, every=self.steps)
        stamps = [(self.next_index + i) * self.period_ns for i in range(len(samples))]
        self.next_index += len(samples)
        rows = self._converter.rows(samples, [t / NS_PER_S for t in stamps],
                                    submerged_weight_n)
        self._remember(samples.data[:, k.C_OMEGA].tolist(), samples.data[:, k.C_MODE].tolist())
        return stamps, rows

    def _remember(self, omega: list[float], mode: list[float]) -> None:
        size = len(self._omega)
        for value, state in zip(omega[-size:], mode[-size:], strict=True):
            self._omega[self._head] = value
            self._stuck[self._head] = state == k.MODE_STUCK
            self._head = (self._head + 1) % size
        self._filled = min(size, self._filled + len(omega))

    def severity(self) -> tuple[Severity, float]:
        """Stick-slip severity of the recent window and its stick fraction (nan if empty)."""
        if self._filled == 0:
            return severity(np.empty(0), 1.0), math.nan
        omega = np.roll(self._omega, -self._head)[-self._filled:]
        stuck = np.roll(self._stuck, -self._head)[-self._filled:]
        return severity(omega, self.sim.targets[0]), float(stuck.mean())

    def set_surface_rpm(self, rpm: float) -> None:
        self.sim.set_inputs(omega_s=self.scales.omega_from_rpm(rpm))

    def set_wob_n(self, wob_n: float) -> None:
        self.sim.set_inputs(w_app=self.scales.w_from_newton(wob_n))

    def reset(self) -> None:
        """Model back to its initial state and setpoints; the simulated clock runs on."""
        self.sim.reset()
        self._filled = 0
