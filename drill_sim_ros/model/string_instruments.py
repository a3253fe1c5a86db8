"""Instruments a controller engineer uses on a distributed string, in the time domain.

ROS-free. Both run the simulator as it runs the string (the same kernel, the same delay
lines), off bottom with the hook fixed, after a short pulse sent up from the bit:

* :func:`identify_modes`: the ring-down of the bit's angular and axial speed under a
  kinematic top drive with no damping; the first natural frequencies are the spectral
  peaks (Hann window, zero padding, parabolic interpolation on the log magnitude), shown
  beside the transfer-matrix ones (:func:`string.analytic_modes_hz`). Then a second
  ring-down of the string with its damping, after a twist near the bit is let go: the
  modes' damping ratios are those of the poles the matrix pencil finds in it
  (:mod:`poles`), shown beside the first-order ones
  (:func:`string.analytic_damping_ratios`).
* :func:`measure_reflection`: the waves meeting the top drive, separated exactly by the
  method of characteristics (b arriving, a = b + 2 Z w leaving), and the drive's
  reflection r(f) = A(f) / B(f) as the ratio of their spectra over a ring-down long enough
  to decay; beside the analytic |Z - Z_TD(i w)| / |Z + Z_TD(i w)| with
  Z_TD(s) = J s + kp + ki / s for the drive's own speed loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

import numpy as np

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model import poles
from drill_sim_ros.model import string as sg
from drill_sim_ros.model.bit_reflection import below, reflection_of_load
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import TopDrive, TopDrivePhysical

PULSE_WIDTH_S = 0.05       # standard deviation of the Gaussian pulse sent from the bit
SAMPLE_HZ = 200.0          # the ring-down is recorded at this rate (modes < 20 Hz)
# the damped ring-down (identify_modes)
TWIST_WIDTH_PERIODS = 0.25  # width of the released twist, s, x the highest mode's frequency
DECAY_NEPERS = 10.0        # the record lasts until its slowest mode has decayed by e^-10,
RECORD_PERIODS = 30.0      # at most 30 periods of mode 1
FIT_SAMPLES = 600          # and at most this many samples after decimation
FILTER_DECAY = 1.5         # the decimation filter lasts at most 1.5 / (largest rate / 2)


@dataclass(frozen=True)
class Modes:
    """Natural frequencies, Hz, identified from the undamped ring-down (None: no peak near
    that mode) and analytic; damping ratios identified from the damped ring-down (None: no
    pole found near that mode) and analytic (first order), mode by mode as the analytic
    frequencies."""

    torsional_identified_hz: list[float | None]
    torsional_analytic_hz: list[float]
    axial_identified_hz: list[float | None]
    axial_analytic_hz: list[float]
    torsional_identified_damping_ratio: list[float | None]
    torsional_analytic_damping_ratio: list[float]
    axial_identified_damping_ratio: list[float | None]
    axial_analytic_damping_ratio: list[float]

    def as_dict(self) -> dict[str, dict[str, list[float | None]]]:
        return {"torsional": {"identified_hz": self.torsional_identified_hz,
                              "analytic_hz": self.torsional_analytic_hz,
                              "identified_damping_ratio":
                                  self.torsional_identified_damping_ratio,
                              "analytic_damping_ratio": self.torsional_analytic_damping_ratio},
                "axial": {"identified_hz": self.axial_identified_hz,
                          "analytic_hz": self.axial_analytic_hz,
                          "identified_damping_ratio": self.axial_identified_damping_ratio,
                          "analytic_damping_ratio": self.axial_analytic_damping_ratio}}


def require_distributed(preset: Preset) -> None:
    if not preset.string.distributed:
        raise ParameterError(f"preset '{preset.name}' has a lumped string; the string "
                             "instruments need 'string: {model: distributed}'")


def reflection_preset(preset: Preset) -> Preset:
    """``preset`` with its string replaced by its top section twice over, undamped and
    out of any well (no wall): a uniform line in which a pulse from the bit meets only the
    top drive (the bottom is made anechoic by :meth:`Simulator.hang_off_bottom`), so the
    waves that come back down are the drive's reflection and nothing else. Scales, rock
    and drive are unchanged. (With the wall of a deviated preset left on, the line at rest
    stuck to it and the "reflection" read 10^6-10^8.)"""
    require_distributed(preset)
    top = preset.string.undamped().sections[0]
    return replace(preset, string=replace(preset.string, sections=(top, top),
                                          bit_inertia_kg_m2=0.0, well=None))


def off_bottom_simulator(preset: Preset, drive: TopDrive, dtau: float | None = None,
                         undamped: bool = False, anechoic: bool = False) -> Simulator:
    """A simulator of ``preset`` with the bit hanging free off bottom, the hook fixed, the
    string untwisted and turning at the preset's speed (no torque, no axial motion)."""
    require_distributed(preset)
    if undamped:
        preset = replace(preset, string=preset.string.undamped())
    sim = Simulator(preset.params, SimConfig(dtau=dtau or preset.dtau, n_nodes=64),
                    top_drive=drive, scales=preset.scales, string=preset.kernel_string,
                    bit_law=preset.bit_law)
    sim.hang_off_bottom(anechoic)
    return sim


def line_columns(sim: Simulator, axial: bool) -> tuple[int, int]:
    """The parts ``lo .. hi - 1`` of the torsional or the axial line in the layout arrays."""
    _, wave_i, _, parts = sim.string_arrays()
    return (parts[0], wave_i.shape[1]) if axial else (0, parts[0])


def _cells_above_bit(wave_i: np.ndarray, lo: int, hi: int
                     ) -> Iterator[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """Part by part from the bit up: (part, slots of its a, slots of its b, the height of
    each of its cells above the bit in cells). The a in the cell h above the bottom of a
    part reaches that bottom in h steps; the b there left it h + 1 steps ago (the layout
    of :func:`string.line_state`)."""
    below = 0
    for j in range(hi - 1, lo - 1, -1):
        n, off, pos = (int(wave_i[sg.W_LEN, j]), int(wave_i[sg.W_OFF, j]),
                       int(wave_i[sg.W_POS, j]))
        h = np.arange(n)
        yield j, off + (pos + h) % n, off + n + (pos - 1 - h) % n, below + h
        below += n


def send_pulse_from_bit(sim: Simulator, axial: bool, amplitude: float,
                        width_steps: float) -> None:
    """An up-going Gaussian pulse centred at the bit at this instant: its upper half in the
    up-going wave above the bit and its lower half as a down-going image that the free bit
    end reflects into the rest (b = -a). ``amplitude`` in the line's force units; the pulse
    stays in the bottom part (cut at its top)."""
    wave, wave_i, _, _ = sim.string_arrays()
    _, a_slots, b_slots, h = next(_cells_above_bit(wave_i, *line_columns(sim, axial)))
    cells = h[:int(8 * width_steps) + 1]
    # b in the cell k above the bit left it k + 1 steps ago; a in the cell k above it
    # reaches it in k steps and leaves again as b = -a: the centre is at the bit now
    wave[b_slots[:cells.size]] += amplitude * np.exp(-0.5 * ((cells + 1) / width_steps) ** 2)
    wave[a_slots[:cells.size]] -= amplitude * np.exp(-0.5 * (cells / width_steps) ** 2)


def release_twist(sim: Simulator, axial: bool, amplitude: float, width_steps: float) -> None:
    """Add a torque (axially a force) T(h) = A (h / w) exp(-(h / w)^2 / 2) to the line at
    the height h above the bit (in cells, w = ``width_steps``), the speeds unchanged: a
    twist let go at this instant. It vanishes at the free bit and is continuous across every
    point damper, so it agrees with the string's own junction conditions and excites its
    modes up to about 1 / (2 pi w) smoothly. ``amplitude`` in the line's force units."""
    wave, wave_i, _, _ = sim.string_arrays()
    for _, a_slots, b_slots, h in _cells_above_bit(wave_i, *line_columns(sim, axial)):
        x = (h + 0.5) / width_steps
        torque = amplitude * x * np.exp(-0.5 * x * x)
        wave[a_slots] += torque                     # T = (a + b) / 2, w = (a - b) / 2 Z
        wave[b_slots] += torque


def _peaks_hz(signal: np.ndarray, sample_hz: float, count: int, f_min_hz: float) -> list[float]:
    """The ``count`` lowest spectral peaks above ``f_min_hz``: maxima of a zero-padded Hann
    spectrum that stand above 1 % of the largest and are the largest within +-10 % of
    their frequency (so no window sidelobe counts), each refined by a parabola through
    the log magnitudes."""
    x = signal - signal.mean()
    n_fft = 1 << (math.ceil(math.log2(x.size)) + 3)
    mag = np.abs(np.fft.rfft(x * np.hanning(x.size), n_fft))
    logm = np.log(mag + 1e-300)
    df = sample_hz / n_fft
    floor = mag.max() * 1e-2
    found: list[float] = []
    for i in range(max(1, int(f_min_hz / df)), mag.size - 1):
        if mag[i] <= floor or mag[i] < mag[i - 1] or mag[i] <= mag[i + 1]:
            continue
        half = max(2, int(0.1 * i))
        if mag[i] < mag[max(0, i - half):i + half + 1].max():
            continue
        a, b, c = logm[i - 1], logm[i], logm[i + 1]
        found.append((i + 0.5 * (a - c) / (a - 2.0 * b + c)) * df)
        if len(found) == count:
            break
    return found


def _sampling(sim: Simulator) -> tuple[int, float]:
    """Steps between the ring-down's samples (about SAMPLE_HZ) and its rate, Hz."""
    every = max(1, round(1.0 / (SAMPLE_HZ * sim.scales.time_s * sim.config.dtau)))
    return every, 1.0 / (every * sim.config.dtau * sim.scales.time_s)


def _ring_down(sim: Simulator, seconds: float, columns: tuple[int, ...]
               ) -> tuple[np.ndarray, float]:
    """Kernel sample columns over ``seconds`` of simulated time at about SAMPLE_HZ, and the
    sampling rate in Hz."""
    every, sample_hz = _sampling(sim)
    steps = sim.steps_for(seconds / sim.scales.time_s)
    rows = sim.advance(steps, every=every).data
    return rows[:, list(columns)], sample_hz


def identify_modes(preset: Preset, count: int = 3, seconds: float = 400.0) -> Modes:
    """The first ``count`` torsional and axial modes of ``preset``'s string (off bottom,
    kinematic top, hook fixed): the natural frequencies identified from an undamped
    ring-down after a pulse from the bit, with the analytic ones (fixed top, free bit); the
    damping ratios identified from a ring-down of the string with its damping
    (:func:`identified_damping_ratios`), with the first-order ones."""
    spec = preset.string
    analytic = {axial: sg.analytic_modes_hz(spec, count, axial=axial) for axial in (False, True)}
    zeta = {axial: sg.analytic_damping_ratios(spec, analytic[axial], axial)
            for axial in (False, True)}
    peaks = [peaks_by_mode(found, analytic[axial])
             for axial, found in enumerate(_undamped_peaks_hz(preset, count, seconds))]
    identified = identified_damping_ratios(preset, analytic, zeta, seconds)
    return Modes(peaks[0], analytic[False], peaks[1], analytic[True],
                 identified[False], zeta[False], identified[True], zeta[True])


def peaks_by_mode(peaks_hz: list[float], modes_hz: list[float],
                  window: float = poles.MODE_WINDOW) -> list[float | None]:
    """For each mode at ``modes_hz``, the spectral peak nearest it within +-``window`` of its
    frequency (the damping poles' window, :func:`poles.damping_ratio_near`), else None: on
    a walled string the wall can damp a mode out of the ring-down, and the lowest peaks
    found are then not modes 1, 2, 3 (listed in turn, they would be named after the wrong
    modes)."""
    out: list[float | None] = []
    for f in modes_hz:
        near = [p for p in peaks_hz if abs(p / f - 1.0) < window]
        out.append(min(near, key=lambda p: abs(p - f)) if near else None)
    return out


def _undamped_peaks_hz(preset: Preset, count: int, seconds: float
                       ) -> tuple[list[float], list[float]]:
    """The spectral peaks of the bit's (angular, axial) speed over ``seconds`` of the
    undamped string's ring-down after a pulse from the bit."""
    drive = TopDrive(mode="kinematic", inertia_ratio=preset.top_drive.inertia_ratio)
    sim = off_bottom_simulator(preset, drive, undamped=True)
    width = PULSE_WIDTH_S / (preset.scales.time_s * sim.wave_dtau)     # in cells
    send_pulse_from_bit(sim, False, 0.05 * preset.params.omega0 * sim.string_arrays()[2][
        sg.W_Z, 0], width)
    send_pulse_from_bit(sim, True, 1.0, width)
    data, sample_hz = _ring_down(sim, seconds, (k.C_OMEGA, k.C_V))
    return (_peaks_hz(data[:, 0], sample_hz, count, 0.02),
            _peaks_hz(data[:, 1], sample_hz, count, 0.02))


@dataclass(frozen=True)
class DampedFit:
    """How one kind of mode is read from the damped ring-down: the decimation, the record
    length (s) and the number of modes below the decimated Nyquist frequency."""

    decimation: poles.Decimation
    record_s: float
    modes_in_band: int


def damped_fit(spec: sg.StringSpec, axial: bool, modes_hz: list[float],
               zetas: list[float], sample_hz: float, seconds: float) -> DampedFit:
    """The record lasts until its slowest mode (by ``zetas``) has decayed by
    e^-DECAY_NEPERS, at most RECORD_PERIODS of mode 1, FIT_SAMPLES decimated samples and
    ``seconds``, plus the filter's transient. The filter is no longer than the time in
    which the fastest-decaying modes (sigma = largest rate / 2) lose e^-FILTER_DECAY."""
    sigma_max = 0.5 * max(sg.line_properties(s, axial).damping_per_s for s in spec.sections)
    decimation = poles.plan_decimation(sample_hz, modes_hz[-1], FILTER_DECAY / sigma_max
                                       if sigma_max > 0.0 else math.inf)
    rate_hz = decimation.rate_hz(sample_hz)
    record_s = min(seconds, RECORD_PERIODS / modes_hz[0], FIT_SAMPLES / rate_hz)
    slowest = min(2.0 * math.pi * f * z for f, z in zip(modes_hz, zetas, strict=True))
    if slowest > 0.0:
        record_s = min(record_s, DECAY_NEPERS / slowest)
    in_band = len(sg.analytic_modes_hz(spec, 64, axial, f_max_hz=0.5 * rate_hz))
    return DampedFit(decimation, record_s + decimation.taps / sample_hz, in_band)


def identified_damping_ratios(preset: Preset, modes_hz: dict[bool, list[float]],
                              zetas: dict[bool, list[float]], seconds: float
                              ) -> dict[bool, list[float | None]]:
    """The damping ratios of the modes at ``modes_hz`` (torsional: False, axial: True),
    identified on the string with its damping, off bottom under a kinematic top with the
    hook fixed, turning steadily (:meth:`Simulator.hang_off_bottom`): a twist near the bit,
    about a quarter period of the highest mode wide, is let go (:func:`release_twist`) and
    the poles of the bit's speeds are fitted (:func:`poles.damping_ratios`). ``zetas``
    (the analytic ratios) only size the record."""
    drive = TopDrive(mode="kinematic", inertia_ratio=preset.top_drive.inertia_ratio)
    sim = off_bottom_simulator(preset, drive)
    sample_hz = _sampling(sim)[1]
    cell_s = preset.scales.time_s * sim.wave_dtau
    fits = {axial: damped_fit(preset.string, axial, modes_hz[axial], zetas[axial], sample_hz,
                              seconds) for axial in (False, True) if modes_hz[axial]}
    out: dict[bool, list[float | None]] = {False: [], True: []}
    if not fits:
        return out
    for axial in fits:
        z_bit = float(sim.string_arrays()[2][sg.W_Z, line_columns(sim, axial)[1] - 1])
        release_twist(sim, axial, 0.05 * preset.params.omega0 * z_bit,
                      TWIST_WIDTH_PERIODS / modes_hz[axial][-1] / cell_s)
    data, sample_hz = _ring_down(sim, max(f.record_s for f in fits.values()),
                                 (k.C_OMEGA, k.C_V))
    for axial, fit in fits.items():
        record = data[:round(fit.record_s * sample_hz), int(axial)]
        out[axial] = poles.damping_ratios(record, sample_hz, fit.decimation,
                                          modes_hz[axial], fit.modes_in_band)
    return out


@dataclass(frozen=True)
class Reflection:
    """|r| of the top drive against frequency: measured and, for the native loop, analytic."""

    f_hz: list[float]
    r_measured: list[float]
    r_analytic: list[float] | None


REFLECTION_TOP_HZ = 20.0     # the usual top of |r|(f): past the collars' ring


def reflection_frequencies(count: int = 16, f_lo_hz: float = 0.05,
                           f_hi_hz: float = REFLECTION_TOP_HZ) -> np.ndarray:
    """Log-spaced frequencies between ``f_lo_hz`` and ``f_hi_hz`` (up to the collars' ring:
    a drive that returns more than it receives there pumps it)."""
    return np.geomspace(f_lo_hz, f_hi_hz, count)


def frequencies_with_modes(spec: sg.StringSpec, count: int = 3,
                           up_to_hz: float = REFLECTION_TOP_HZ) -> np.ndarray:
    """:func:`reflection_frequencies` and the string's first ``count`` torsional modes
    (fixed top, free bit), sorted: |r| at a mode is what decides whether it is absorbed.
    With ``up_to_hz`` above the usual top, three more log-spaced frequencies up to it (a
    sampled controller's |r| up to near its Nyquist rate)."""
    above = np.geomspace(REFLECTION_TOP_HZ, up_to_hz, 4)[1:] \
        if up_to_hz > REFLECTION_TOP_HZ else np.empty(0)
    return np.unique(np.concatenate((reflection_frequencies(), above,
                                     sg.analytic_modes_hz(spec, count))))


def analytic_reflection(z_string: float, inertia: float, kp: float, ki: float,
                        f_hz: np.ndarray) -> np.ndarray:
    """|Z - Z_TD(i w)| / |Z + Z_TD(i w)| with Z_TD(s) = J s + kp + ki / s (SI)."""
    s = 2j * np.pi * f_hz
    z_td = inertia * s + kp + ki / s
    return np.abs(z_string - z_td) / np.abs(z_string + z_td)


def top_waves(rows: np.ndarray, z_top: float) -> tuple[np.ndarray, np.ndarray]:
    """From kernel rows (every step): the wave arriving at the top, b = T - Z w_s, and the
    wave leaving it, a = b + 2 Z w_s(next step) (module string), over all rows but the
    last."""
    return waves_at_top(rows[:, k.C_T_PIPE], rows[:, k.C_OMEGA_S], z_top)


def waves_at_top(torque: np.ndarray, speed: np.ndarray, z_top: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`top_waves` from the string torque at the top and the drive speed, every
    step."""
    b = torque[:-1] - z_top * speed[:-1]
    return b + 2.0 * z_top * speed[1:], b


def spectral_ratio(a: np.ndarray, b: np.ndarray, sample_hz: float,
                   f_hz: np.ndarray) -> np.ndarray:
    """|A(f) / B(f)| at ``f_hz`` (:func:`complex_spectral_ratio`)."""
    return np.abs(complex_spectral_ratio(a, b, sample_hz, f_hz))


def complex_spectral_ratio(a: np.ndarray, b: np.ndarray, sample_hz: float,
                           f_hz: np.ndarray) -> np.ndarray:
    """A(f) / B(f) at ``f_hz`` by direct Fourier sums of the whole records (both decay to
    nothing at the end, so no window is needed)."""
    t = np.arange(a.size) / sample_hz
    out = []
    for f in f_hz:
        e = np.exp(-2j * np.pi * f * t)
        out.append(np.dot(a, e) / np.dot(b, e))
    return np.array(out)


def _top_records(sim: Simulator, z_top: float, seconds: float, block: int = 32
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """The waves at the top over ``seconds``, from every step, block-averaged by ``block``
    steps (a linear filter on both, which their ratio does not see); and their rate, Hz."""
    steps = sim.steps_for(seconds / sim.scales.time_s) // block * block
    a_parts, b_parts, last = [], [], None
    while steps > 0:
        n = min(block << 14, steps)
        rows = sim.advance(n, every=1).data
        rows = rows if last is None else np.vstack((last, rows))
        a, b = top_waves(rows, z_top)
        m = a.size // block * block
        a_parts.append(a[:m].reshape(-1, block).mean(axis=1))
        b_parts.append(b[:m].reshape(-1, block).mean(axis=1))
        last = rows[m:]
        steps -= n
    return (np.concatenate(a_parts), np.concatenate(b_parts),
            1.0 / (block * sim.config.dtau * sim.scales.time_s))


def reflection_of(run: Callable[[bool], tuple[np.ndarray, np.ndarray]], sample_hz: float,
                  f_hz: np.ndarray, with_phase: bool = False) -> np.ndarray:
    """|r(f)| (``with_phase``: r(f) = A / B, complex) from two identical runs ``run(pulse)``
    -> (a, b), with and without the pulse from the bit: their difference is the pulse's own
    waves at the top (the loop is linear off bottom), so a drive or controller that is not
    at rest when the pulse comes does not count."""
    a1, b1 = run(True)
    a0, b0 = run(False)
    ratio = complex_spectral_ratio(a1 - a0, b1 - b0, sample_hz, f_hz)
    return ratio if with_phase else np.abs(ratio)


def measure_reflection(preset: Preset, seconds: float = 120.0,
                       f_hz: np.ndarray | None = None) -> Reflection:
    """The reflection of torsional waves by ``preset``'s own drive (its speed loop),
    measured in the time domain on :func:`reflection_preset` (one pulse up, its reflection
    down, nothing else), with the analytic curve."""
    f_hz = reflection_frequencies() if f_hz is None else f_hz
    drive = preset.top_drive.with_(mode="speed")
    line = reflection_preset(preset)

    def run(pulse: bool) -> tuple[np.ndarray, np.ndarray]:
        sim = off_bottom_simulator(line, drive, anechoic=True)
        if pulse:
            z_top = float(sim.string_arrays()[2][sg.W_Z, 0])
            width = PULSE_WIDTH_S / (line.scales.time_s * sim.wave_dtau)   # cells
            send_pulse_from_bit(sim, False, 0.05 * line.params.omega0 * z_top, width)
        a, b, _ = _top_records(sim, z_top_of(sim), seconds)
        return a, b

    sample_hz = 1.0 / (32 * line.dtau * line.scales.time_s)
    ratio = reflection_of(run, sample_hz, f_hz)
    phys = preset.drive
    z_si = preset.string.sections[0].torsional_impedance_nm_s
    analytic = analytic_reflection(z_si, phys.inertia_kg_m2, phys.kp_nm_s, phys.ki_nm, f_hz)
    return Reflection([float(f) for f in f_hz], [float(r) for r in ratio],
                      [float(r) for r in analytic])


def z_top_of(sim: Simulator) -> float:
    """The impedance of the string's top part, kernel units."""
    return float(sim.string_arrays()[2][sg.W_Z, 0])


MATCHED_DRIVE_INERTIA_KG_M2 = 5.0   # the matched top's inertia: J w << Z up to a few Hz
MATCHED_DRIVE_KI_NM = 1.0           # and its integral gain: ki / w << Z from 0.01 Hz


def matched_drive(preset: Preset) -> TopDrive:
    """A speed loop that absorbs what comes up the pipe: kp = Z of the top section, a small
    inertia and integral gain (Z_TD = J s + Z + ki / s close to Z in the first modes' band),
    no torque limit, no motor lag; its integral holds the steady torque from the start."""
    z = preset.string.sections[0].torsional_impedance_nm_s
    return TopDrivePhysical(mode="speed", inertia_kg_m2=MATCHED_DRIVE_INERTIA_KG_M2,
                            kp_nm_s=z, ki_nm=MATCHED_DRIVE_KI_NM,
                            max_torque_nm=math.inf).scaled(preset.scales)


def on_bottom_simulator(preset: Preset, omega0: float, w0: float) -> Simulator:
    """``preset`` drilling steadily (RGD07's trivial state, no perturbation) at the scaled
    speed ``omega0`` and weight ``w0`` under :func:`matched_drive`."""
    require_distributed(preset)
    params = preset.params.with_(omega0=omega0, w0=w0)
    return Simulator(params, SimConfig(dtau=preset.dtau, n_nodes=64),
                     top_drive=matched_drive(preset), scales=preset.scales,
                     string=preset.kernel_string, bit_law=preset.bit_law,
                     perturb_v=0.0, perturb_omega=0.0)


def _record_top_with_pulse(sim: Simulator, omega0: float, amplitude: float,
                           width_steps: float, seconds: float, block: int = 32
                           ) -> tuple[np.ndarray, np.ndarray]:
    """The string torque at the top and the drive speed (kernel units), every step
    block-averaged by ``block``, over
    ``seconds`` from now, while the drive's speed setpoint makes a Gaussian bump of
    ``amplitude`` (kernel speed units; standard deviation ``width_steps`` steps, centred 4
    widths from now, set in 200 stairs): the drive sends a torque pulse down the pipe."""
    stair = max(1, round(8.0 * width_steps / 200))
    torque, speed = [], []

    def take(n: int) -> None:
        rows = sim.advance(n, every=1).data
        torque.append(rows[:, k.C_T_PIPE].copy())
        speed.append(rows[:, k.C_OMEGA_S].copy())

    for i in range(200):
        x = (i * stair - 4.0 * width_steps) / width_steps
        sim.set_inputs(omega_s=omega0 + amplitude * math.exp(-0.5 * x * x))
        take(stair)
    sim.set_inputs(omega_s=omega0)
    left = sim.steps_for(seconds / sim.scales.time_s) - 200 * stair
    while left > 0:
        take(min(left, 1 << 18))
        left -= 1 << 18
    t, w = np.concatenate(torque), np.concatenate(speed)
    m = t.size // block * block
    return t[:m].reshape(-1, block).mean(axis=1), w[:m].reshape(-1, block).mean(axis=1)


def laplace_ratio(a: np.ndarray, b: np.ndarray, sample_hz: float,
                  s: np.ndarray) -> np.ndarray:
    """A(s) / B(s) at Laplace values ``s`` (1/s) by direct sums over the records from
    their first sample (t = 0): with Re s > 0 the records are weighted by exp(-Re(s) t), so
    a record cut before it has died out still gives the transfer function there."""
    t = np.arange(a.size) / sample_hz
    out = []
    for value in s:
        e = np.exp(-value * t)
        out.append(np.dot(a, e) / np.dot(b, e))
    return np.array(out)


BIT_PULSE_SHARE = 0.2      # the pulse's speed bump, share of the drilling speed
BIT_SETTLE_S = 0.5         # steady drilling before the pulse
BIT_RECORD_S = 8.0         # and the record after it: the drilling itself departs later


def measure_bit_reflection(preset: Preset, omega0: float, w0: float, s: np.ndarray,
                           settle_s: float = BIT_SETTLE_S,
                           seconds: float = BIT_RECORD_S,
                           on_bottom: bool = True) -> np.ndarray:
    """r_bit(s), complex, MEASURED on bottom in steady drilling at the scaled speed
    ``omega0`` and weight ``w0``, at Laplace values ``s`` (Re s > 0 for a record this
    short). After ``settle_s`` a torque pulse is sent down from a matched top
    (:func:`matched_drive`); the string torque and the speed at the top are recorded for
    ``seconds``, and a run without the pulse is subtracted (the drilling moves by itself).
    Their ratio is the impedance the string shows at the top; the pipe's lossy line is
    taken off it (:func:`bit_reflection.below`: a wave split with the lossless Z0 would
    mix the lossy line's own scattering in) to give the load below the pipe, the BHA and
    bit, and its reflection (:func:`bit_reflection.reflection_of_load`, torque waves, -1
    at a free end). The record is short because steady drilling on RGD07's law is itself
    unstable (its axial mode): after some seconds the two runs part and their difference
    is no longer the pulse's (docs/string.md). ``on_bottom`` False: the bit hanging free
    (:meth:`Simulator.hang_off_bottom`), the BHA's own reflection."""
    def run(pulse: bool) -> tuple[np.ndarray, np.ndarray]:
        sim = on_bottom_simulator(preset, omega0, w0)
        if not on_bottom:
            sim.hang_off_bottom()
        sim.advance(sim.steps_for(settle_s / preset.scales.time_s))
        width = PULSE_WIDTH_S / (preset.scales.time_s * sim.config.dtau)       # steps
        return _record_top_with_pulse(sim, omega0, BIT_PULSE_SHARE * omega0 if pulse
                                      else 0.0, width, seconds)

    sc = preset.scales
    sample_hz = 1.0 / (32 * preset.dtau * sc.time_s)
    t1, w1 = run(True)
    t0, w0_ = run(False)
    z_top = laplace_ratio(t1 - t0, w1 - w0_, sample_hz, s) * sc.torque_nm * sc.time_s
    pipe = preset.string.sections[0]
    return reflection_of_load(pipe, below(pipe, z_top, s), s)
