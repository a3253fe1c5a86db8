"""Stateful simulator around the compiled kernels: buffers, inputs, snapshots, samples.

The :class:`Simulator` owns the state vector, the bottom-hole profile (bounded memory:
``n_nodes`` floats) and the statistics; it validates its inputs once, at the boundary.
All quantities are dimensionless (RGD07 eqs. 19-24); :mod:`drill_sim_ros.model.params`
converts to SI. The top drive's commands and readings also come in SI (the ``*_rad_s`` and
``*_nm`` members), through the :class:`Scales` the simulator was given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from operator import attrgetter

import numpy as np

from drill_sim_ros.model import bit_rock as br
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import top_drive as td
from drill_sim_ros.model.analysis import TrivialSolution, trivial_solution
from drill_sim_ros.model.errors import (
    EnergyFault,
    HistoryOverflow,
    NumericalFault,
    ParameterError,
)
from drill_sim_ros.model.formation import Layer
from drill_sim_ros.model.params import UNIT_SCALES, DimensionlessParams, Scales

METHODS = ("profile", "exact")
REBASE_DEPTH = 1.0e4     # rebase U and angles beyond this, to keep differences exact
REBASE_CHECK_STEPS = 1 << 16   # steps between rebasing checks (U, PHI move far less)
DEFAULT_NODES = 2048

# The parameter vector (kernel.P_*), one row a slot: (name, slot, source), the source an
# attribute of the simulator (dotted). No scale: every source is in kernel units already,
# converted once where it is built (TopDrivePhysical.scaled, string.kernel_string,
# FrictionWeakening.scaled, DepthOfCutLimit.scaled).
# Set elsewhere: the drive's mode (at start and by set_top_drive_mode), the rock of the
# layer the bit is in (beta, lambda, the cutting factor, the next top: _apply_layer), off
# bottom and the tag speed (hang_off_bottom, set_off_bottom, start_at_rest).
PARAMETERS: tuple[tuple[str, int, str], ...] = (
    ("n", k.P_N, "params.n"),
    ("psi", k.P_PSI, "params.psi"),
    ("dtau", k.P_DT, "config.dtau"),
    ("omega_rate", k.P_OMEGA_RATE, "config.omega_rate"),
    ("w_rate", k.P_W_RATE, "config.w_rate"),
    ("tau_avg", k.P_TAU_AVG, "config.tau_avg"),
    ("td_inertia", k.P_TD_INERTIA, "top_drive.inertia_ratio"),
    ("td_kp", k.P_TD_KP, "top_drive.kp"),
    ("td_ki", k.P_TD_KI, "top_drive.ki"),
    ("td_max_torque", k.P_TD_MAX_TORQUE, "top_drive.max_torque"),
    ("td_lag_alpha", k.P_TD_LAG_ALPHA, "top_drive_lag_alpha"),
    ("td_torque_rate", k.P_TD_TORQUE_RATE, "top_drive.max_torque_rate"),
    ("string", k.P_STRING, "string.model"),
    ("parts_t", k.P_PARTS_T, "torsional_parts"),
    ("bit_inertia", k.P_BIT_INERTIA, "string.bit_inertia"),
    ("hook_kp", k.P_HOOK_KP, "string.hook_kp"),
    ("hook_ki", k.P_HOOK_KI, "string.hook_ki"),
    ("bha_part", k.P_BHA_PART, "string.bha_part"),
    ("pickup", k.P_PICKUP, "string.pickup"),
    ("clearance", k.P_CLEARANCE, "string.clearance"),
    ("substeps", k.P_SUBSTEPS, "string.substeps"),
    ("bit_law", k.P_BIT_LAW, "bit_law.law"),
    ("bit_law_a", k.P_BIT_LAW_A, "bit_law.a"),
    ("bit_law_b", k.P_BIT_LAW_B, "bit_law.b"),
    ("bit_law_alpha", k.P_BIT_LAW_ALPHA, "bit_law_alpha"),
    ("doc_max", k.P_DOC_MAX, "bit_law.doc_max"),
    ("beta_limit", k.P_BETA_LIMIT, "bit_law.beta_limit"),
)


@dataclass(frozen=True)
class SimConfig:
    """Numerical settings. dtau: step; n_nodes: profile nodes per blade sector;
    method: 'profile' (production) or 'exact' (reference time-history delay);
    omega_rate / w_rate: ramp limits of the surface inputs per unit tau (inf = none);
    tau_avg: statistics window start; history_capacity: samples kept by 'exact'.
    """

    dtau: float = 1e-4
    n_nodes: int = DEFAULT_NODES
    method: str = "profile"
    omega_rate: float = math.inf
    w_rate: float = math.inf
    tau_avg: float = 0.0
    history_capacity: int = 1 << 21

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dtau) and 0.0 < self.dtau <= 0.05):
            raise ParameterError(f"parameter 'dtau' = {self.dtau!r} must be in (0, 0.05]")
        if not 16 <= self.n_nodes <= 1 << 22:
            raise ParameterError(f"parameter 'n_nodes' = {self.n_nodes!r} must be in "
                                 "[16, 4194304]")
        if self.method not in METHODS:
            raise ParameterError(f"parameter 'method' = {self.method!r} must be one of "
                                 f"{METHODS}")
        for name in ("omega_rate", "w_rate"):
            value = getattr(self, name)
            if math.isnan(value) or value <= 0.0:
                raise ParameterError(f"parameter '{name}' = {value!r} must be > 0 (inf: none)")


@dataclass
class Snapshot:
    """Everything needed to resume a run bit-for-bit."""

    state: np.ndarray
    targets: np.ndarray
    profile: np.ndarray
    acc: np.ndarray
    history: np.ndarray | None
    meta: np.ndarray | None
    depth_offset: float
    angle_offset: float
    top_drive_mode: float = td.TD_KINEMATIC
    wave: np.ndarray | None = None
    wave_pos: np.ndarray | None = None
    layer_index: int = -1
    junctions: np.ndarray | None = None     # the junctions' state rows (W_LAST .. W_BIT)
    off_bottom: float = 0.0


@dataclass
class Samples:
    """Rows of kernel samples, shape (rows, N_COLS); columns are ``kernel.C_*``."""

    data: np.ndarray
    depth_offset: float = 0.0
    angle_offset: float = 0.0

    def __len__(self) -> int:
        return self.data.shape[0]

    def column(self, index: int) -> np.ndarray:
        """One column; depth and angles with the rebasing offsets added back."""
        col = self.data[:, index]
        if index == k.C_U:
            return col + self.depth_offset
        if index in (k.C_PHI, k.C_PHI_S):
            return col + self.angle_offset
        return col


def _check_input(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ParameterError(f"input '{name}' = {value!r} must be finite and >= 0")
    return value


class Simulator:
    """The RGD07 bit at the bottom of a drill string, stepped with bounded memory.

    Starts on the trivial solution (eq. 34) of ``params``, with the history before tau = 0
    being the trivial motion, and the velocity perturbations ``perturb_v`` and
    ``perturb_omega`` added at tau = 0. ``top_drive`` (default: kinematic, the paper's
    imposed speed) turns the top of the string; ``string`` (default: RGD07's lumped spring)
    is the string in kernel units (:func:`string.kernel_string`); ``bit_law`` (default:
    RGD07's) the bit's torque law in kernel units (:class:`bit_rock.BitLaw`); ``scales``
    (default: unit scales) converts the SI top-drive members.
    """

    def __init__(self, params: DimensionlessParams, config: SimConfig | None = None,
                 perturb_v: float = 0.0, perturb_omega: float = 0.0,
                 top_drive: td.TopDrive | None = None, scales: Scales = UNIT_SCALES,
                 string: sg.KernelString = sg.LUMPED, bit_law: br.BitLaw = br.RGD07_LAW
                 ) -> None:
        self.params = params
        self.config = config or SimConfig()
        self.top_drive = top_drive or td.TopDrive()
        self.scales = scales
        self.string = string
        self._layers: tuple[Layer, ...] = ()
        self._cell_depths: dict[bool, np.ndarray] = {}
        self._layer_index = -1
        self._wave_layout()
        for name, value in (("perturb_v", perturb_v), ("perturb_omega", perturb_omega)):
            if not math.isfinite(value):
                raise ParameterError(f"parameter '{name}' = {value!r} must be finite")
        self._perturb = (float(perturb_v), float(perturb_omega))
        self.bit_law = bit_law
        self._prm = np.zeros(k.N_PARAMS)
        self._prm[k.P_TD_MODE] = td.mode_index(self.top_drive.mode)
        if self.top_drive.mode == "speed":
            td.check_speed_loop(self.top_drive, self.config.dtau, self.scales)
        self._prm[k.P_TAG_SPEED] = math.inf      # the WOB loop unbounded until a tag
        self._fill_params()
        self.reset()

    # ---- set-up ---------------------------------------------------------------------
    def _fill_params(self, prefix: str = "") -> None:
        """The parameter vector's slots from :data:`PARAMETERS`, those whose source starts
        with ``prefix`` (all by default)."""
        for _, slot, source in PARAMETERS:
            if source.startswith(prefix):
                self._prm[slot] = attrgetter(source)(self)

    def _fill_drive(self, drive: td.TopDrive) -> None:
        """The drive's inertia ratio, gains, torque limit, lag and torque rate limit into the
        parameters (its mode: the callers)."""
        self.top_drive = drive
        self._fill_params("top_drive")

    @property
    def bit_law_alpha(self) -> float:
        """The share by which the speed the bit law reads follows the bit's per step
        (BitLaw.alpha)."""
        return self.bit_law.alpha(self.config.dtau)

    @property
    def top_drive_lag_alpha(self) -> float:
        """The drive's motor lag per step (TopDrive.lag_alpha)."""
        return self.top_drive.lag_alpha(self.config.dtau)

    @property
    def torsional_parts(self) -> int:
        """The distributed string's parts of the torsional line (0: lumped)."""
        return self._parts[0] if self._parts else 0

    def _wave_layout(self) -> None:
        """The delay lines of a distributed string at this step (none for the lumped one);
        every part must span at least one step."""
        self._balance_mark = np.zeros((2, sg.N_BALANCE))   # the guard's (string.balance)
        self._balance_stale = True           # the mark is taken again before the next run
        if self.string.model != sg.STRING_DISTRIBUTED:
            self._wave_i, self._wave_f, self._parts = k.NO_WAVE_I, k.NO_WAVE_F, ()
            self._wave = k.NO_WAVE
            return
        self._wave_i, self._wave_f, self._wave, self._parts = sg.build_lines(
            self.string.lines, self.wave_dtau)
        if self._wave_i[sg.W_LEN].min() < 1:
            raise ParameterError(
                f"a string section (or damping part) is shorter than one step of the wave "
                f"guide (dtau = {self.config.dtau:g} x string.bit_substeps = "
                f"{self.string.substeps}); lengthen it, merge it with its neighbour, lower "
                "string.damping_points or string.bit_substeps (a walled string's cells are "
                "cut for the preset's numerics.dtau)")

    @property
    def wave_dtau(self) -> float:
        """The wave guide's step, the time a cell of its delay lines spans: dtau times the
        bit law's steps per wave step (string.StringSpec.bit_substeps)."""
        return self.config.dtau * self.string.substeps

    @property
    def distributed(self) -> bool:
        return self.string.model == sg.STRING_DISTRIBUTED

    def _init_wave(self, triv: TrivialSolution) -> None:
        """Steady drilling along the string: the trivial torque at the bit and the speed
        everywhere, each part carrying the drag of the dampers below it, and the drive's
        loop holding the torque at the top; the applied weight at the bit and the trivial
        rate of penetration axially; the hook feeds at it."""
        if not self.distributed:
            return
        self._wave_i[sg.W_POS] = 0
        self._fill_steady(triv.torque, self.params.omega0, self.params.w0, triv.v)
        self._state[k.S_V_HOOK] = triv.v
        self._state[k.S_HOOK_INTEGRAL] = triv.v

    def _fill_steady(self, bit_torque: float, speed: float, bit_force: float,
                     axial_speed: float) -> None:
        """Both lines in steady motion (:func:`string.fill_steady`), and the drive's loop
        and torque command on the torque that this leaves at the top."""
        parts_t, parts = self._parts[0], self._wave_i.shape[1]
        top_torque = sg.fill_steady(self._wave, self._wave_i, self._wave_f, 0, parts_t,
                                    bit_torque, speed, axial_speed)
        sg.fill_steady(self._wave, self._wave_i, self._wave_f, parts_t, parts, bit_force,
                       axial_speed, speed)
        self._wave_f[sg.W_WORK:] = 0.0         # the works summed (the guard's balance)
        self._balance_stale = True
        st = self._state
        st[k.S_SUB_COUNT:k.S_SUB_V_BIT + 1] = 0.0     # a new wave step starts now
        st[k.S_TD_INTEGRAL] = st[k.S_MOTOR_TORQUE] = top_torque
        self._targets[k.I_MOTOR_TORQUE] = top_torque

    @property
    def trivial(self) -> TrivialSolution:
        """Trivial solution (eq. 34) for the parameters the run started with, its torque
        the bit law's at the top-drive speed (RGD07's law: eq. 34 itself)."""
        triv, p, law = trivial_solution(self.params), self.params, self.bit_law
        if law.law == br.LAW_RGD07:
            return triv
        return replace(triv, torque=law.torque(triv.depth_of_cut, triv.wearflat, p.beta,
                                               p.omega0))

    def reset(self) -> None:
        """Back to tau = 0 on the trivial solution, perturbations re-applied; the top-drive
        mode in force stays (it is a setting), its loop restarts on the trivial torque."""
        triv = self.trivial
        p = self.params
        st = np.zeros(k.N_STATE)
        st[k.S_V] = triv.v + self._perturb[0]
        st[k.S_OMEGA] = st[k.S_LAW_OMEGA] = p.omega0 + self._perturb[1]
        st[k.S_PHI_S] = triv.torque           # pipe twist carries the trivial torque
        st[k.S_OMEGA_S] = p.omega0
        st[k.S_W_APP] = p.w0
        st[k.S_OMEGA_REF] = p.omega0
        st[k.S_TD_INTEGRAL] = triv.torque     # the loop holds the trivial torque
        st[k.S_MOTOR_TORQUE] = triv.torque
        self._state = st
        self._targets = np.array([p.omega0, p.w0, triv.torque])
        self._acc = k.new_accumulators()
        self._depth_offset = 0.0
        self._angle_offset = 0.0
        self._unchecked_steps = 0
        self._init_profile(triv)
        self._init_history(triv)
        if self._prm[k.P_OFF_BOTTOM] == k.OFF_BOTTOM_LIFTED:
            self._prm[k.P_OFF_BOTTOM] = 0.0  # the trivial solution drills on bottom
        self._init_wave(triv)
        self.set_formation(self._layers)
        self.fault: str | None = None

    def _init_profile(self, triv: TrivialSolution) -> None:
        """Rock surface left by the trivial motion (eq. 6 with U = v0 tau, PHI = omega0 tau).

        Node j (angle j*h ahead of the bit, j >= 1) was last cut one sector earlier, at
        depth slope * (j*h - sector) with slope = v0/omega0 = delta0 / (2 pi); node 0 was
        just cut at U = 0 and held -delta0/n before.
        """
        n_nodes = self.config.n_nodes
        sector = 2.0 * math.pi / self.params.n
        slope = triv.depth_of_cut / (2.0 * math.pi)
        angles = np.arange(n_nodes) * (sector / n_nodes)
        self._profile = slope * (angles - sector)
        self._profile[0] = 0.0
        self._state[k.S_NODE] = 0.0
        self._state[k.S_FRAC] = 0.0
        self._state[k.S_H_OLD] = -slope * sector

    def _init_history(self, triv: TrivialSolution) -> None:
        """Trivial (PHI, U) history over one sector and a bit more, for the exact path."""
        if self.config.method != "exact":
            self._hist = None
            self._meta = None
            return
        cap = self.config.history_capacity
        sector = 2.0 * math.pi / self.params.n
        dphi = self.params.omega0 * self.config.dtau
        count = min(cap // 2, math.ceil(sector / dphi) + 2)
        phi = -dphi * np.arange(count - 1, -1, -1)
        self._hist = np.zeros((2, cap))
        self._hist[0, :count] = phi
        self._hist[1, :count] = triv.depth_of_cut / (2.0 * math.pi) * phi
        self._meta = np.array([count % cap, count, 0], dtype=np.int64)

    # ---- inputs -----------------------------------------------------------------------
    def set_inputs(self, omega_s: float | None = None, w_app: float | None = None,
                   motor_torque: float | None = None) -> None:
        """Surface setpoints (dimensionless top-drive speed, applied weight and the motor
        torque of the torque mode). They take effect at the next step, the speed and the
        weight through the ramp limits of the config, the torque within the drive's limit.
        """
        if omega_s is not None:
            self._targets[k.I_OMEGA_S] = _check_input("omega_s", omega_s)
        if w_app is not None:
            self._targets[k.I_W_APP] = _check_input("w_app", w_app)
        if motor_torque is not None:
            if not math.isfinite(motor_torque):
                raise ParameterError(f"input 'motor_torque' = {motor_torque!r} must be finite")
            self._targets[k.I_MOTOR_TORQUE] = float(motor_torque)

    @property
    def targets(self) -> tuple[float, float]:
        """Commanded (omega_s, w_app)."""
        return float(self._targets[0]), float(self._targets[1])

    # ---- the top drive (RGD07 eq. 12 extended; see model.top_drive) ----------------------
    @property
    def top_drive_mode(self) -> str:
        """'kinematic', 'speed' or 'torque'."""
        return td.MODES[int(self._prm[k.P_TD_MODE])]

    def set_top_drive_mode(self, mode: str) -> None:
        """Switch the drive's mode at the next run, without a bump: the drive's speed
        carries over; entering ``speed`` the loop's setpoint starts at the present drive
        speed and its integral at the present motor torque (then ramps to the commanded
        setpoint); entering ``torque`` the present motor torque is held until
        :meth:`set_motor_torque_nm` commands another; entering ``kinematic`` the drive
        speed goes to the setpoint through the ramp limit of the config.

        It writes the state, so call it between runs, never while a compiled caller is
        inside ``kernel.advance`` (which holds the state in locals and writes them back);
        the commands are single stores into the targets, read when a run starts."""
        index = td.mode_index(mode)
        if index == td.TD_SPEED:
            td.check_speed_loop(self.top_drive, self.config.dtau, self.scales)
        if index == int(self._prm[k.P_TD_MODE]):
            return                             # no switch: the loop and the command stay
        st = self._state
        held = td.within_limit(float(st[k.S_MOTOR_TORQUE]), self._prm[k.P_TD_MAX_TORQUE])
        if index == td.TD_SPEED:
            st[k.S_OMEGA_REF] = st[k.S_OMEGA_S]
            st[k.S_TD_INTEGRAL] = held
        elif index == td.TD_TORQUE:
            self._targets[k.I_MOTOR_TORQUE] = held
        self._prm[k.P_TD_MODE] = index

    def set_top_drive(self, drive: td.TopDrive) -> None:
        """New drive parameters (gains, limit, inertia) from the next run, and its mode
        through :meth:`set_top_drive_mode`; call it between runs, like that."""
        self._fill_drive(drive)
        self.set_top_drive_mode(drive.mode)

    def set_speed_ramp(self, rate: float) -> None:
        """The ramp limit of the drive speed's target, per unit tau (``config.omega_rate``,
        > 0; inf: none), from the next run. A speed prescribed as a time series sets it with
        each sample's target (``model.replay``), so the drive goes linearly between them."""
        self.config = replace(self.config, omega_rate=float(rate))    # validated there
        self._fill_params("config.omega_rate")

    def set_speed_setpoint_rad_s(self, speed_rad_s: float) -> None:
        """Drive speed setpoint in rad/s (kinematic and speed modes), from the next step."""
        self.set_inputs(omega_s=self.scales.omega_from_rad_s(_check_input("speed_rad_s",
                                                                          speed_rad_s)))

    def set_motor_torque_nm(self, torque_nm: float) -> bool:
        """Motor torque command in N m (torque mode), from the next step. The drive applies
        it within +-max torque (``top_drive.within_limit``, in its step); returns True when
        the command lies beyond that limit."""
        torque_nm = float(torque_nm)
        if not math.isfinite(torque_nm):
            raise ParameterError(f"input 'motor_torque_nm' = {torque_nm!r} must be finite")
        self._targets[k.I_MOTOR_TORQUE] = self.scales.t_from_nm(torque_nm)
        return abs(self._targets[k.I_MOTOR_TORQUE]) > self._prm[k.P_TD_MAX_TORQUE]

    @property
    def drive_speed_rad_s(self) -> float:
        """The drive's (quill's) speed now, rad/s (the encoder's reading)."""
        return self.scales.rad_s(float(self._state[k.S_OMEGA_S]))

    @property
    def motor_torque_nm(self) -> float:
        """The motor torque of the last step, N m."""
        return self.scales.tob_nm(float(self._state[k.S_MOTOR_TORQUE]))

    @property
    def string_torque_nm(self) -> float:
        """The string torque at the quill now, C (PHI_S - PHI), N m (the torque sub's)."""
        return self.scales.tob_nm(float(self._state[k.S_PHI_S] - self._state[k.S_PHI]))

    # ---- stepping ---------------------------------------------------------------------
    @property
    def tau(self) -> float:
        return float(self._state[k.S_TAU])

    @property
    def steps(self) -> int:
        return int(self._state[k.S_STEP])

    def steps_for(self, duration: float) -> int:
        """Whole steps covering ``duration`` (rounded to the nearest step)."""
        if not math.isfinite(duration) or duration < 0.0:
            raise ParameterError(f"duration {duration!r} must be finite and >= 0")
        return round(duration / self.config.dtau)

    def advance(self, n_steps: int, every: int = 0) -> Samples:
        """Advance ``n_steps``; return a sample every ``every`` global steps (0: none).

        Raises :class:`NumericalFault` if the state became non-finite (then call reset()).
        """
        rows = 0 if every <= 0 else max(0, n_steps) // every + 1
        out = np.empty((rows, k.N_COLS))
        written = self.advance_into(out, n_steps, every)
        return Samples(out[:written], self._depth_offset, self._angle_offset)

    def advance_into(self, out: np.ndarray, n_steps: int, every: int,
                     sample_end: bool = False) -> int:
        """:meth:`advance` into the caller's array (rows of ``kernel.C_*`` columns, at least
        ``n_steps // every + 1``, one more with ``sample_end``); returns the rows written.
        With ``sample_end`` the last row is the sample of the state the run ended in (see
        :meth:`sample_into`), in the same compiled call. Allocates nothing: the node's 10 ms
        tick uses it. The rows hold depth and angles less :attr:`offsets`.
        """
        if n_steps < 0:
            raise ParameterError(f"n_steps = {n_steps!r} must be >= 0")
        self._open_run(n_steps)
        kernel = k.advance_and_sample if sample_end else k.advance
        written, left = 0, n_steps
        while True:
            start = self.steps
            status, rows = kernel(*self._kernel_arrays(), out[written:], *self._wave_arrays(),
                                  left, every, self.exact)
            written += rows
            left -= self.steps - start
            if status != k.STATUS_LAYER:
                break
            self._next_layer()
            if left == 0:
                if sample_end:                 # the end sample is still due
                    status, rows = kernel(*self._kernel_arrays(), out[written:],
                                          *self._wave_arrays(), 0, every, self.exact)
                    written += rows
                else:
                    status = k.STATUS_OK
                break
        self._close_run(n_steps, status)
        return written

    # ---- formation layers (model.formation) --------------------------------------------
    def set_formation(self, layers: tuple[Layer, ...]) -> None:
        """Rock layers by depth (kernel terms, tops in L* below the start); the layer the bit
        is in now applies from the next step, the others where the bit reaches their top.
        An empty tuple is the preset's rock throughout."""
        self._layers = layers
        self._layer_index = -1
        depth = self._state[k.S_U] + self._depth_offset
        while (self._layer_index + 1 < len(layers)
               and layers[self._layer_index + 1].top <= depth):
            self._layer_index += 1
        self._apply_layer()

    def _apply_layer(self) -> None:
        """The bit law's rock parameters of the current layer and the next layer's top."""
        layers, i, p = self._layers, self._layer_index, self.params
        layer = layers[i] if i >= 0 else None
        self._prm[k.P_CUT] = 1.0 if layer is None else layer.cut_factor
        self._prm[k.P_BETA] = p.beta if layer is None else layer.beta
        self._prm[k.P_LAM] = p.lam if layer is None else layer.lam
        self._prm[k.P_LAYER_U] = (layers[i + 1].top - self._depth_offset
                                  if i + 1 < len(layers) else math.inf)

    @property
    def layer_index(self) -> int:
        """The formation layer the bit is in (-1: the preset's rock, above the first)."""
        return self._layer_index

    def _next_layer(self) -> None:
        """The bit reached the next layer's top (kernel STATUS_LAYER)."""
        self._layer_index += 1
        self._apply_layer()

    def sample_into(self, out: np.ndarray) -> None:
        """The sample of the current state into ``out`` (one row of ``kernel.C_*`` columns,
        depth and angles less :attr:`offsets`): what the next step records at its start,
        read from a dry step (``kernel._steps``), so the simulator itself does not move."""
        if self.fault is not None:
            raise NumericalFault(f"simulator faulted ({self.fault}); call reset()")
        k.advance_and_sample(*self._kernel_arrays(), out.reshape(1, k.N_COLS),
                             *self._wave_arrays(), 0, 0, self.exact)

    def _wave_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The arguments of ``kernel.advance`` after ``out``: the string's delay lines."""
        return self._wave, self._wave_i, self._wave_f

    def _kernel_arrays(self) -> tuple[np.ndarray, ...]:
        """The arguments of ``kernel.advance`` before ``out``: state, parameters, targets,
        profile, history, history meta, accumulators."""
        if self._hist is None:               # the profile method (no exact-delay history)
            return (self._state, self._prm, self._targets, self._profile, k.NO_HISTORY,
                    k.NO_META, self._acc)
        return (self._state, self._prm, self._targets, self._profile, self._hist, self._meta,
                self._acc)

    @property
    def exact(self) -> bool:
        return self._hist is not None

    def _open_run(self, n_steps: int) -> None:
        """Before a run of ``n_steps``: raises after a fault, and rebases when a check is
        due (never during a run, so :attr:`offsets` hold for all its rows)."""
        if self.fault is not None:
            raise NumericalFault(f"simulator faulted ({self.fault}); call reset()")
        if self._balance_stale and self.distributed:
            sg.mark_lines(self._wave, self._wave_i, self._wave_f, self._parts[0],
                          self.wave_dtau, self._balance_mark)
            self._balance_stale = False
        if self._unchecked_steps + n_steps >= REBASE_CHECK_STEPS:
            self._rebase()
            self._unchecked_steps = 0

    def _close_run(self, n_steps: int, status: int) -> None:
        """After a run of ``n_steps`` that ended with kernel ``status``: raises
        NumericalFault or HistoryOverflow when it failed."""
        self._unchecked_steps += n_steps
        self._check(status)
        self._check_energy(n_steps)

    def _check_energy(self, n_steps: int) -> None:
        """The physics guard (string.balance): after a run of ``n_steps``, each wave line's
        energy against the work done on it since the last check (drive or hook at the top,
        bit, wall, dampers), within the rounding of the scheme (string.call_tolerance), and
        no wall or damper that ever gave the string energy. Else the simulator faults
        (:class:`EnergyFault`) naming the element (the line and its junction), its depth,
        the time and the energy in J, instead of returning numbers."""
        if not self.distributed:
            return
        finding, line, column, value, bound = sg.check_lines(
            self._wave, self._wave_i, self._wave_f, self._parts[0], self.wave_dtau,
            self._balance_mark, sg.call_tolerance(n_steps // self.string.substeps + 1))
        if finding == sg.BALANCE_OK:
            return
        self.fault = self._energy_fault(finding, line, column, value, bound)
        raise EnergyFault(self.fault)

    def _energy_fault(self, finding: int, line: int, column: int, value: float,
                      bound: float) -> str:
        """The one-line message of a finding of :func:`string.check_lines`."""
        sc = self.scales
        joule = sc.force_n * sc.length_m if line else sc.torque_nm   # per kernel unit
        name = "axial" if line else "torsional"
        head = f"energy fault at t = {self.tau * sc.time_s:.6g} s (tau = {self.tau:.6g}): "
        if finding == sg.BALANCE_DRIFT:
            return (head + f"the {name} line's energy balance is off by {value * joule:.4g} J "
                    f"over the last run (stored change - (top work - bit work - wall work - "
                    f"damper work); tolerance {bound * joule:.3g} J): the string "
                    f"{'created' if value > 0.0 else 'lost'} energy that no element accounts "
                    "for (a bug in the wave step or a write into its waves)")
        local = column - (self._parts[0] if line else 0)
        depth_m = float(sum(self.string.lines[line].length_m[:local + 1]))
        where = f"the {name} line's junction {local} ({depth_m:.1f} m below the top)"
        if finding == sg.BALANCE_WALL:
            return (head + f"the wall at {where} gave the string {-value * joule:.4g} J (its "
                    "friction can only take energy: a negative normal force or friction "
                    "limit there)")
        return (head + f"the damper at {where} gave the string {-value * joule:.4g} J (a "
                "viscous loss can only take energy: a negative damping there)")

    @property
    def offsets(self) -> tuple[float, float]:
        """(depth, angle) to add to the depth and angles of the rows of the last advance."""
        return self._depth_offset, self._angle_offset

    def _check(self, status: int) -> None:
        if status == k.STATUS_NONFINITE:
            self.fault = f"non-finite state at tau = {self.tau:.6g}"
            raise NumericalFault(self.fault)
        if status == k.STATUS_HISTORY_FULL:
            self.fault = "exact-delay history full"
            raise HistoryOverflow(f"{self.fault}: raise SimConfig.history_capacity")
        if status == k.STATUS_RUNAWAY:
            st = self._state
            self.fault = (f"runaway at tau = {self.tau:.6g}: bit speed {st[k.S_OMEGA]:.6g}, "
                          f"drive speed {st[k.S_OMEGA_S]:.6g}, motor torque "
                          f"{st[k.S_MOTOR_TORQUE]:.6g} (scaled): the bit would pass a whole "
                          "blade sector in one step")
            raise NumericalFault(self.fault)

    def _rebase(self) -> None:
        """Shift depth and angles by whole amounts so differences stay exact (U grows)."""
        st = self._state
        if abs(st[k.S_U]) > REBASE_DEPTH:
            shift = math.floor(st[k.S_U])
            st[k.S_U] -= shift
            self._profile -= shift
            st[k.S_H_OLD] -= shift
            if self._hist is not None:
                self._hist[1] -= shift
            self._depth_offset += shift
            self._apply_layer()                # the next top, in the new depth frame
        if abs(st[k.S_PHI]) > REBASE_DEPTH:
            turns = 2.0 * math.pi * math.floor(st[k.S_PHI] / (2.0 * math.pi))
            st[k.S_PHI] -= turns
            st[k.S_PHI_S] -= turns
            if self._hist is not None:
                self._hist[0] -= turns
            self._angle_offset += turns

    # ---- the string along depth (distributed) -----------------------------------------
    def string_profile(self, axial: bool = False
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The string now, top to bottom, one value per cell of its delay lines:
        ``(depth_m, speed, force)`` with depth below the top in m, the speed (angular,
        rad/s; axial, m/s) and the torque (N m) or axial force above the hanging weight (N),
        in SI through :attr:`scales`. Empty arrays for the lumped string."""
        if not self.distributed:
            empty = np.zeros(0)
            return empty, empty, empty
        parts_t = self._parts[0]
        lo, hi = (parts_t, self._wave_i.shape[1]) if axial else (0, parts_t)
        force, speed, _ = sg.line_state(self._wave, self._wave_i, self._wave_f, lo, hi)
        if axial not in self._cell_depths:       # the layout is fixed: computed once
            self._cell_depths[axial] = sg.cell_depths_m(self.string.lines[1 if axial else 0],
                                                        self._wave_i, lo)
        depth = self._cell_depths[axial]
        sc = self.scales
        if axial:
            return depth, speed * sc.length_m / sc.time_s, force * sc.force_n
        return depth, speed / sc.time_s, force * sc.torque_nm

    def string_cells(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The torsional (speed rad/s, torque N m) of the distributed string now at
        ``cells`` only (ascending int64 indices into :meth:`string_profile`'s arrays): the
        values it gives there, without reading the other cells."""
        force, speed = sg.cells_state(self._wave, self._wave_i, self._wave_f, 0, cells)
        sc = self.scales
        return speed / sc.time_s, force * sc.torque_nm

    def top_waves(self) -> tuple[float, float]:
        """The torsional waves at the top of the string now, kernel units: (a, the one the
        drive sent down at the last wave step; b, the one arriving from below)."""
        wave, wave_i = self._wave, self._wave_i
        off, n, pos = (int(wave_i[sg.W_OFF, 0]), int(wave_i[sg.W_LEN, 0]),
                       int(wave_i[sg.W_POS, 0]))
        return float(wave[off + (pos - 1) % n]), float(wave[off + n + pos])

    def string_energy(self) -> float:
        """Kinetic + strain energy of the distributed string now, in kernel units (torque
        unit C x rad for the torsional line, force unit x L* for the axial one)."""
        if not self.distributed:
            return 0.0
        parts_t, dtau = self._parts[0], self.wave_dtau
        return (sg.line_energy(self._wave, self._wave_i, self._wave_f, 0, parts_t, dtau)
                + sg.line_energy(self._wave, self._wave_i, self._wave_f, parts_t,
                                 self._wave_i.shape[1], dtau))

    def hang_off_bottom(self, anechoic: bool = False) -> None:
        """The bit hangs free off bottom (no bit-rock forces), the hook is fixed, and the
        string turns steadily at the drive's speed with no axial motion, twisted only by its
        dampers' drag (none when undamped), as the string instruments start
        (``drill_sim modes``, ``reflection``).
        ``anechoic``: the torsional line's bottom sends nothing back up (a matched end)."""
        self._prm[k.P_OFF_BOTTOM] = 2.0 if anechoic else 1.0
        st = self._state
        st[k.S_PHI_S] = st[k.S_PHI]
        st[k.S_OMEGA] = st[k.S_LAW_OMEGA] = st[k.S_OMEGA_S]
        st[k.S_TD_INTEGRAL] = st[k.S_MOTOR_TORQUE] = 0.0
        st[k.S_V] = st[k.S_V_HOOK] = st[k.S_HOOK_INTEGRAL] = 0.0
        self._targets[k.I_MOTOR_TORQUE] = 0.0
        if self.distributed:                 # twisted only by its dampers' drag
            self._fill_steady(0.0, st[k.S_OMEGA_S], 0.0, 0.0)

    def start_at_rest(self) -> None:
        """The bit picked up off bottom, the string at rest and untwisted, hanging from the
        hook: drive, string and bit still, the speed loop's setpoint, integral and torque
        zero, every wall junction stuck, the rock the string's clearance below the bit (as
        :meth:`set_off_bottom` leaves it; ``False`` then tags bottom through the bit law).
        ``drill_sim startup`` starts here; set the speed target and its ramp rate to start
        rotating. Needs the distributed string."""
        self.set_off_bottom(True)
        self._state[k.S_OMEGA_S] = 0.0
        self._targets[k.I_OMEGA_S] = 0.0
        self.hang_off_bottom()
        self._prm[k.P_OFF_BOTTOM] = k.OFF_BOTTOM_LIFTED
        self._state[k.S_OMEGA_REF] = 0.0
        st = self._state            # the rock a clearance below the bit (and a millionth
        clearance = self.string.clearance * (1.0 + 1e-6)   # more: the hook holds, no ulp off)
        drop = clearance + st[k.S_U] - min(self._profile.min(), st[k.S_H_OLD])
        self._profile += drop
        st[k.S_H_OLD] += drop
        if self._hist is not None:
            self._hist[1] += drop

    def set_off_bottom(self, off: bool) -> None:
        """Pick the bit up off bottom (``True``): the hook rises at the string's pick-up
        speed until the bit is its clearance above the rock, and holds it; the bit leaves
        the rock through the bit law's own contact (eq. 31). ``False``: tag bottom again,
        the hook back on its WOB loop lowering the string until the bit cuts (the law's
        own transition from off bottom, no jump). Needs the distributed string's hook."""
        if not self.distributed:
            raise ParameterError("off bottom needs the distributed string (a hook that "
                                 "holds it); RGD07's lumped string is always on bottom")
        self._prm[k.P_OFF_BOTTOM] = k.OFF_BOTTOM_LIFTED if off else 0.0
        if not off:                  # the driller slacks off onto the rock at the tag speed
            self._prm[k.P_TAG_SPEED] = self.string.tag_speed

    @property
    def off_bottom(self) -> bool:
        """Whether the bit is picked up (or hung) off bottom, as set."""
        return bool(self._prm[k.P_OFF_BOTTOM] != 0.0)

    def wall_work(self) -> float:
        """The work the wall's friction has taken from the string since the start (reset,
        :meth:`hang_off_bottom`), kernel units (both lines; 0 without a well)."""
        if not self.distributed:
            return 0.0
        return float(self._wave_f[sg.W_WORK].sum()) * self.wave_dtau

    def energy_balance(self) -> np.ndarray:
        """Each wave line's energy balance now (string.line_balance), rows (torsional,
        axial), columns ``string.B_*``: the energy it holds, and the work done at its top,
        at the bit, by the wall and by its dampers since the start (reset,
        :meth:`hang_off_bottom`), kernel units as :meth:`string_energy`; zeros for the lumped
        string, which holds no waves."""
        out = np.zeros((2, sg.N_BALANCE))
        if self.distributed:
            sg.mark_lines(self._wave, self._wave_i, self._wave_f, self._parts[0],
                          self.wave_dtau, out)
        return out

    def string_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, ...]]:
        """The delay lines as they are (wave, layout int, layout float, parts per line), for
        instruments that send a pulse into the string; writes to ``wave`` are the state (the
        guard's balance starts again from them at the next run)."""
        self._balance_stale = True
        return self._wave, self._wave_i, self._wave_f, self._parts

    # ---- state access -----------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        """A deep copy of the whole state; :meth:`restore` resumes it bit-for-bit."""
        return Snapshot(self._state.copy(), self._targets.copy(), self._profile.copy(),
                        self._acc.copy(), None if self._hist is None else self._hist.copy(),
                        None if self._meta is None else self._meta.copy(),
                        self._depth_offset, self._angle_offset, float(self._prm[k.P_TD_MODE]),
                        *((self._wave.copy(), self._wave_i[sg.W_POS].copy())
                          if self.distributed else (None, None)), self._layer_index,
                        self._wave_f[sg.W_LAST:].copy() if self.distributed else None,
                        float(self._prm[k.P_OFF_BOTTOM]))

    def restore(self, snap: Snapshot) -> None:
        """Resume from a :meth:`snapshot` of a simulator with the same settings."""
        if snap.profile.shape != self._profile.shape:
            raise ParameterError("snapshot profile size differs from this simulator's n_nodes")
        self._state = snap.state.copy()
        self._targets = snap.targets.copy()
        self._profile = snap.profile.copy()
        self._acc = snap.acc.copy()
        self._hist = None if snap.history is None else snap.history.copy()
        self._meta = None if snap.meta is None else snap.meta.copy()
        self._depth_offset = snap.depth_offset
        self._angle_offset = snap.angle_offset
        self._prm[k.P_TD_MODE] = snap.top_drive_mode
        self._layer_index = min(snap.layer_index, len(self._layers) - 1)
        self._apply_layer()
        if snap.wave is not None and self.distributed:
            if snap.wave.shape != self._wave.shape:
                raise ParameterError("snapshot string layout differs from this simulator's")
            self._wave = snap.wave.copy()
            self._wave_i[sg.W_POS] = snap.wave_pos
            if snap.junctions is not None:
                self._wave_f[sg.W_LAST:] = snap.junctions
            self._balance_stale = True
        self._prm[k.P_OFF_BOTTOM] = snap.off_bottom
        self.fault = None

    @property
    def state(self) -> np.ndarray:
        """Read-only view of the state vector (indices ``kernel.S_*``)."""
        view = self._state.view()
        view.flags.writeable = False
        return view

    @property
    def profile(self) -> np.ndarray:
        """Rock height per node of one blade sector (copy, depth offset added)."""
        return self._profile + self._depth_offset

    @property
    def accumulators(self) -> np.ndarray:
        """Raw statistics (indices ``kernel.A_*``); see :func:`analysis.run_statistics`."""
        return self._acc.copy()

    def restart_extremes(self) -> None:
        """New running min and max of the bit speed; the sums run on (windowed statistics)."""
        self._acc[k.A_OMEGA_MIN] = math.inf
        self._acc[k.A_OMEGA_MAX] = -math.inf

    def reset_statistics(self, tau_avg: float | None = None) -> None:
        """Start a new statistics window at ``tau_avg`` (default: now)."""
        self._prm[k.P_TAU_AVG] = self.tau if tau_avg is None else tau_avg
        self._acc = k.new_accumulators()
