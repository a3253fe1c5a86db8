"""The simulation as a node sees it: SI setpoints in, a block of SI samples per run out.

ROS-free. A :class:`SimSession` owns the :class:`Simulator` and is the only caller of it for
sim_node. It refines the step so a whole number of steps fills one publish period, stamps
samples with an integer-nanosecond simulated clock that never goes back (not even on reset),
converts them to SI telemetry rows (:mod:`drill_sim_ros.model.telemetry`) and keeps windowed
statistics of the bit speed for the stick-slip severity.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from drill_sim_ros.model import defaults
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.analysis import Severity, severity_of
from drill_sim_ros.model.depth_profile import MAX_DEPTHS, DepthSampler, StringSample
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.formation import layers_from_dicts
from drill_sim_ros.model.measurement import RigSensors
from drill_sim_ros.model.params import GROUPS
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.telemetry import (
    MEASURED_COLUMNS,
    NO_COMMAND_S,
    NS_PER_S,
    field_scales,
    set_wob_estimate,
    stamped_si_rows,
)
from drill_sim_ros.model.top_drive import TopDrivePhysical, check_speed_loop

WINDOW_BUCKETS = 20


@dataclass(frozen=True)
class SessionConfig:
    """What the node's parameters fix for the lifetime of a session (SI units)."""

    preset: Preset
    publish_rate_hz: float = 100.0
    dtau_max: float = defaults.DTAU
    n_nodes: int = defaults.N_NODES
    perturb_v: float = 0.0
    applied_wob_n: float | None = None
    surface_rpm: float | None = None
    top_drive_accel_rpm_s: float = 0.0   # 0: no limit
    wob_rate_n_s: float = 0.0            # 0: no limit
    window_s: float = defaults.WINDOW_S
    submerged_weight_n: float = 0.0      # for the hook load
    top_drive: TopDrivePhysical | None = None   # SI; None: the preset's (Preset.drive)
    sensors: RigSensors | None = None           # None: perfect surface sensors
    command_delay_s: float = 0.0         # transport delay of the set_* inputs (0: none)
    formation: tuple[dict, ...] = ()     # rock layers by depth (model.formation, SI keys)
    string_rate_hz: float = 0.0          # string profiles per s of sim time (0: none)
    string_depths: int = MAX_DEPTHS      # depths of each profile


@dataclass(slots=True)
class Block:
    """Samples of one run: ``rows`` (count, N_FIELDS) SI in ``TELEMETRY_FIELDS`` order,
    ``stamps_ns`` (count,) their simulated time, ``offsets`` the (depth, angle) rebasing
    offsets already added to the rows' depth and angles, ``strings`` the string profiles
    taken in the block (at :attr:`SimSession.string_depths_m`; see ``string_rate_hz``).
    (Not frozen: a frozen dataclass costs microseconds per tick to build.)"""

    rows: np.ndarray
    stamps_ns: np.ndarray
    offsets: tuple[float, float]
    strings: list[StringSample] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.stamps_ns)


def period_ns(publish_rate_hz: float) -> int:
    """One publish period of simulated time in whole nanoseconds."""
    return round(NS_PER_S / publish_rate_hz)


def steps_per_period(period_tau: float, dtau_max: float) -> int:
    """The fewest whole steps of at most ``dtau_max`` that fill ``period_tau``."""
    return max(1, math.ceil(period_tau / dtau_max * (1.0 - 1e-12)))


def build_simulator(cfg: SessionConfig, period_tau: float, steps: int) -> Simulator:
    """The simulator of ``cfg`` with initial setpoints, ramp limits and the drive in model
    units."""
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
    return Simulator(params, config, perturb_v=cfg.perturb_v,
                     top_drive=session_drive(cfg).scaled(sc), scales=sc,
                     string=cfg.preset.kernel_string, bit_law=cfg.preset.bit_law)


def session_drive(cfg: SessionConfig) -> TopDrivePhysical:
    """The drive ``cfg`` starts with, SI: its own, else the preset's."""
    return cfg.preset.drive if cfg.top_drive is None else cfg.top_drive


class SimSession:
    """Advances whole publish periods into a reusable array of kernel samples."""

    def __init__(self, cfg: SessionConfig) -> None:
        self.cfg = cfg
        self.scales = cfg.preset.scales
        self.period_ns = period_ns(cfg.publish_rate_hz)
        period_tau = self.period_ns / NS_PER_S / self.scales.time_s
        self.steps = steps_per_period(period_tau, cfg.dtau_max)
        self.sim = build_simulator(cfg, period_tau, self.steps)
        self.drive = session_drive(cfg)       # the drive in force, SI
        if cfg.formation:
            self.set_formation(list(cfg.formation))
        self.submerged_weight_n = cfg.submerged_weight_n
        self.command_stamp_ns: int | None = None    # stamp of the command in force, if any
        self.sensors = cfg.sensors or RigSensors()
        self._perfect_sensors = self.sensors.perfect
        self._factors = field_scales(self.scales)
        self._samples = np.empty((2, k.N_COLS))   # kernel rows of a run (grows as needed)
        # compile now, not on the first tick (no _block: it would move the sensors' noise)
        self.sim.advance_into(self._samples, 0, self.steps, sample_end=True)
        stamped_si_rows(self._samples[:1], 0.0, 0.0, self._factors, 0, self.period_ns, 0.0,
                        NO_COMMAND_S)
        self.next_index = 0          # sample counter: stamps = index * period_ns
        # The severity window: snapshots of the kernel's running sums at the end of each of
        # its WINDOW_BUCKETS parts, the extremes restarted after each (no per-sample work).
        window = max(1, round(cfg.window_s * cfg.publish_rate_hz))     # in samples
        buckets = min(WINDOW_BUCKETS, window)
        self._bucket_samples = max(1, round(window / buckets))
        self._snapshots: deque[np.ndarray] = deque(maxlen=buckets + 1)
        self._bucket_end = self._bucket_samples
        # inputs on their way to the drive: (due stamp ns, setter, value), in due order
        self.command_delay_ns = round(cfg.command_delay_s * NS_PER_S)
        if not (math.isfinite(cfg.command_delay_s) and self.command_delay_ns >= 0):
            raise ParameterError(f"command delay {cfg.command_delay_s!r} s must be >= 0")
        self._in_transit: deque[tuple[int, Callable[[float], None], float]] = deque()
        self._part = np.empty((2, k.N_COLS))      # one part of a split period
        self._strings = string_sampler(cfg, self.sim)
        self.string_every = string_every(cfg) if self._strings else 0   # periods
        self._taken: list[StringSample] = []      # string profiles of the run under way

    @property
    def string_depths_m(self) -> np.ndarray:
        """The depths of the string profiles, m (empty: none are taken)."""
        return self._strings.depths_m if self._strings else np.zeros(0)

    @property
    def string_names(self) -> list[str]:
        """The joint name of each of :attr:`string_depths_m`."""
        return self._strings.names if self._strings else []

    @property
    def dtau(self) -> float:
        return self.sim.config.dtau

    @property
    def sim_time_ns(self) -> int:
        """Simulated time of the current state (the stamp of its sample)."""
        return self.next_index * self.period_ns

    def current(self) -> Block:
        """The sample of the current state, stamped :attr:`sim_time_ns` (at start: t = 0, the
        sample a controller reacts to before the first period)."""
        self.sim.sample_into(self._samples[0])
        self._take_string()
        return self._block(self._samples[:1], self.next_index)

    def run(self, periods: int) -> Block:
        """Advance ``periods`` publish periods under the inputs set now (zero-order hold):
        their block, sample i being the state at the END of period i, stamped
        ``sim_time_ns + (i + 1) * period_ns`` (before the run). Raises ``NumericalFault``.
        """
        if periods <= 0:
            return self._block(self._samples[:0], self.next_index + 1)
        if periods + 1 > self._samples.shape[0]:
            self._samples = np.empty((periods + 1, k.N_COLS))
        first = self.next_index
        done = 0
        while self._in_transit and done < periods:      # inputs arrive within a period
            self._samples[done + 1] = self._split_period()
            self._take_string()
            done += 1
        while done < periods:
            # rows 0..n-1: the state at the start of each period; row n: the end (the same
            # state as the next part's row 0); parts end where a string profile is due
            part = self._periods_to_string(periods - done)
            rows = self.sim.advance_into(self._samples[done:], part * self.steps,
                                         self.steps, sample_end=True)
            self._advanced(rows - 1)
            self._take_string()
            done += part
        return self._block(self._samples[1:periods + 1], first + 1)

    def _periods_to_string(self, left: int) -> int:
        """Periods to run before the next string profile is due, at most ``left``."""
        every = self.string_every
        if every == 0:
            return left
        return min(left, every - self.next_index % every)

    def _take_string(self) -> None:
        """The string profile of the current state, when one is due at this stamp."""
        if self.string_every and self.next_index % self.string_every == 0:
            speed, torque = self.sim.string_cells(self._strings.cells)
            self._taken.append(self._strings.sample_cells(speed, torque, self.sim_time_ns))

    def _split_period(self) -> np.ndarray:
        """One period with the inputs due in it applied at their step (the step nearest
        their due time); the kernel sample at its end."""
        start_ns, done = self.sim_time_ns, 0
        while self._in_transit:
            due_ns, setter, value = self._in_transit[0]
            at = max(0, round((due_ns - start_ns) * self.steps / self.period_ns))
            if at >= self.steps:
                break
            if at > done:
                self.sim.advance_into(self._part, at - done, self.steps)
                done = at
            self._in_transit.popleft()
            setter(value)
        rows = self.sim.advance_into(self._part, self.steps - done, self.steps,
                                     sample_end=True)
        self._advanced(1)
        return self._part[rows - 1]

    def _input(self, setter: Callable[[float], None], value: float) -> None:
        """``setter(value)`` now, or after the command delay (from the current stamp)."""
        if self.command_delay_ns == 0:
            setter(value)
        else:
            self._in_transit.append((self.sim_time_ns + self.command_delay_ns, setter, value))

    def _block(self, samples: np.ndarray, first_index: int) -> Block:
        """SI block of kernel rows, the first stamped ``first_index * period_ns``."""
        command_s = NO_COMMAND_S if self.command_stamp_ns is None else \
            self.command_stamp_ns / NS_PER_S
        offsets = self.sim.offsets
        rows, stamps_ns = stamped_si_rows(samples, offsets[0], offsets[1], self._factors,
                                          first_index * self.period_ns, self.period_ns,
                                          float(self.submerged_weight_n), command_s)
        if not self._perfect_sensors:          # si_rows gives the truth, perfect sensors
            self.sensors.measure_into(rows, MEASURED_COLUMNS)     # in place
            set_wob_estimate(rows, float(self.submerged_weight_n))
        if not self._taken:
            return Block(rows, stamps_ns, offsets)
        strings, self._taken = self._taken, []
        return Block(rows, stamps_ns, offsets, strings)

    def _advanced(self, count: int) -> None:
        """Count ``count`` samples advanced and take the severity window's snapshot when it
        is due."""
        self.next_index += count
        if self.next_index >= self._bucket_end:
            self._snapshots.append(self.sim.accumulators)
            self.sim.restart_extremes()
            self._bucket_end = self.next_index + self._bucket_samples

    def severity(self) -> tuple[Severity, float]:
        """Stick-slip severity of the last ``window_s`` (to within 1/WINDOW_BUCKETS of it, or
        one period), from every step, and its stick fraction (nan before the first step)."""
        now = self.sim.accumulators
        full = len(self._snapshots) == self._snapshots.maxlen
        start = self._snapshots[0] if full else k.new_accumulators()
        parts = [*list(self._snapshots)[1 if full else 0:], now]
        steps = now[k.A_COUNT] - start[k.A_COUNT]
        if steps <= 0:
            return Severity(math.nan, math.nan, math.nan, math.nan, math.nan), math.nan
        lo = min(float(p[k.A_OMEGA_MIN]) for p in parts)
        hi = max(float(p[k.A_OMEGA_MAX]) for p in parts)
        mean = float(now[k.A_OMEGA] - start[k.A_OMEGA]) / steps
        stuck = float(now[k.A_STUCK] - start[k.A_STUCK]) / steps
        return severity_of(lo, hi, mean, self.sim.targets[0]), stuck

    def run_info(self) -> dict[str, object]:
        """What this session runs, for a reader of its samples alone: the preset, the six
        groups it started with (RGD07 eqs. 23-24), the scales t*, L*, force and torque units
        (eqs. 19-20) and the sampling."""
        p, sc = self.sim.params, self.scales
        return {
            "preset": self.cfg.preset.name,
            "groups": {name: getattr(p, name) for name in GROUPS},
            "t_star_s": sc.time_s, "l_star_m": sc.length_m,
            "force_unit_n": sc.force_n, "torque_unit_nm": sc.torque_nm,
            "publish_rate_hz": self.cfg.publish_rate_hz, "period_ns": self.period_ns,
            "dtau": self.dtau, "steps_per_period": self.steps,
            "string": self.string_info(),
        }

    def string_info(self) -> dict[str, object]:
        """The string of the run: its model and, when distributed, the sections top to
        bottom (radii and length m, density kg/m^3, moduli Pa, damping rates 1/s), the lumped
        bit inertia kg m^2 and the depths m of the string profiles (none: not sampled)."""
        spec = self.cfg.preset.string
        if not spec.distributed:
            return {"model": spec.model}
        return {"model": spec.model,
                "sections": [asdict(section) for section in spec.sections],
                "bit_inertia_kg_m2": spec.bit_inertia_kg_m2, "length_m": spec.length_m,
                "profile_depths_m": self.string_depths_m.tolist(),
                "profile_period_ns": self.string_every * self.period_ns}

    def set_surface_rpm(self, rpm: float) -> None:
        """The drive's speed setpoint, from now plus the command delay."""
        self._input(self._set_rpm, rpm)

    def set_wob_n(self, wob_n: float) -> None:
        """The applied WOB setpoint, from now plus the command delay."""
        self._input(self._set_wob, wob_n)

    def set_motor_torque_nm(self, torque_nm: float) -> None:
        """The motor torque command of the torque mode, from now plus the command delay; the
        drive applies it within its limit (``top_drive.within_limit``)."""
        self._input(self.sim.set_motor_torque_nm, torque_nm)

    def set_off_bottom(self, off: bool) -> None:
        """Pick the bit up off bottom (True) or tag bottom again (False), from now plus the
        command delay (Simulator.set_off_bottom; ParameterError on the lumped string, now)."""
        if not self.sim.distributed:
            self.sim.set_off_bottom(off)            # raises: the lumped string has no hook
        self._input(self._set_off_bottom, 1.0 if off else 0.0)

    def start_at_rest(self) -> None:
        """The bit picked up off bottom with everything at rest and untwisted, now
        (Simulator.start_at_rest: a start-up after a connection)."""
        self.sim.start_at_rest()

    def _set_off_bottom(self, off: float) -> None:
        self.sim.set_off_bottom(off == 1.0)

    @property
    def off_bottom(self) -> bool:
        """Whether the bit is picked up off bottom (as last applied)."""
        return self.sim.off_bottom

    def _set_rpm(self, rpm: float) -> None:
        self.sim.set_inputs(omega_s=self.scales.omega_from_rpm(rpm))

    def _set_wob(self, wob_n: float) -> None:
        self.sim.set_inputs(w_app=self.scales.w_from_newton(wob_n))

    def check_top_drive(self, drive: TopDrivePhysical) -> None:
        """ParameterError (one line, with the bound) when ``drive`` in speed mode would be
        unstable at this session's step; nothing changes."""
        if drive.mode == "speed":
            check_speed_loop(drive.scaled(self.scales), self.dtau, self.scales)

    def set_top_drive(self, drive: TopDrivePhysical) -> None:
        """New drive gains, limit and mode (SI) from the next period, without a bump; the
        inertia is fixed for a session."""
        self.sim.set_top_drive(drive.scaled(self.scales))
        self.drive = drive

    def check_formation(self, layers: list[dict]) -> None:
        """ParameterError (one line naming the layer and key) if ``layers`` are not valid."""
        if layers:
            layers_from_dicts(layers, self.cfg.preset.rock)

    def set_formation(self, layers: list[dict]) -> None:
        """Rock layers by depth below the start (SI keys of model.formation.LAYER_KEYS), from
        the next period; ``[]``: the preset's rock throughout."""
        self.sim.set_formation(layers_from_dicts(layers, self.cfg.preset.rock) if layers
                               else ())

    def reset(self) -> None:
        """Model back to its initial state and setpoints; the simulated clock runs on."""
        self.sim.reset()
        self.sensors.reset()
        self._in_transit.clear()
        self._snapshots.clear()
        self._bucket_end = self.next_index + self._bucket_samples


def string_sampler(cfg: SessionConfig, sim: Simulator) -> DepthSampler | None:
    """The sampler of the string profiles (None: a lumped string or ``string_rate_hz`` 0)."""
    spec = cfg.preset.string
    if not (spec.distributed and cfg.string_rate_hz > 0):
        return None
    return DepthSampler(sim.string_profile()[0], spec.length_m, cfg.string_depths)


def string_every(cfg: SessionConfig) -> int:
    """Publish periods between string profiles: the nearest whole number to
    publish_rate_hz / string_rate_hz, at least 1 (profiles go out on the samples whose index
    is a multiple of it, at most one per sample)."""
    return max(1, round(cfg.publish_rate_hz / cfg.string_rate_hz))
