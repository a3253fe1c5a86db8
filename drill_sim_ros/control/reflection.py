"""The top drive's reflection of torsional waves with a controller in the loop (ROS-free).

``drill_sim reflection --controller NAME``: the same measurement as
:func:`drill_sim_ros.model.string_instruments.measure_reflection`, but through the closed-loop
bench (:class:`~drill_sim_ros.control.bench.Bench`), the controller reacting to the surface
sensors once per control period. The waves at the top are separated from what the bench
records at the end of each period, the string torque at the quill T and the drive speed w:
a = T + Z w leaving, b = T - Z w arriving (Z of the top section). Two identical runs, with
and without the pulse from the bit, are subtracted, so what the controller does on its own
(settling off bottom) does not count; the loop is linear there.
"""

from __future__ import annotations

import numpy as np

from drill_sim_ros.control.bench import Bench, build_controller
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import string_instruments as si
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import Preset, load_preset
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX


def _top_waves_through_bench(scenario: Scenario, preset: Preset, pulse: bool,
                             settle_periods: int) -> tuple[np.ndarray, ...]:
    """(a, b) at the top, SI (N m), at the end of every control period of ``scenario`` on
    the instrument's uniform anechoic line (string_instruments.reflection_preset), after
    ``settle_periods`` (the pulse, if any, leaves the bit then); the controller is tuned
    from ``preset`` itself."""
    bench = Bench(scenario, si.reflection_preset(preset))
    sim = bench.session.sim
    sim.hang_off_bottom(anechoic=True)
    z_top = float(sim.string_arrays()[2][sg.W_Z, 0])
    controller = build_controller(scenario, preset)
    z_si = bench.preset.string.sections[0].torsional_impedance_nm_s
    torque_col = TELEMETRY_INDEX["surface_torque_nm"]
    speed_col = TELEMETRY_INDEX["surface_rpm"]
    count = bench.periods - settle_periods
    a, b = np.empty(count), np.empty(count)
    command = controller.update(bench.measurement())
    for i in range(bench.periods):
        if pulse and i == settle_periods:
            width = si.PULSE_WIDTH_S / (bench.preset.scales.time_s * sim.config.dtau)
            si.send_pulse_from_bit(sim, False, 0.05 * bench.preset.params.omega0 * z_top,
                                   width)
        row = bench.step(command)
        if i >= settle_periods:
            torque, speed = row[torque_col], row[speed_col] / RPM_PER_RAD_S
            a[i - settle_periods] = torque + z_si * speed
            b[i - settle_periods] = torque - z_si * speed
        if not bench.done:
            command = controller.update(bench.measurement())
    return a, b


CONTROL_RATE_HZ = 100.0  # the bench's control rate, the default of a scenario
NYQUIST_SHARE = 0.9      # |r| with a controller is measured up to this share of its Nyquist


def band_top_hz(control_rate_hz: float) -> float:
    """The top of |r|(f) with a controller sampling at ``control_rate_hz``: near its Nyquist
    rate, where a sampled law lags most (docs/closed-loop.md)."""
    return NYQUIST_SHARE * 0.5 * control_rate_hz


def measure_reflection_with(preset_name: str, controller: str, mode: str = "speed",
                            seconds: float = 120.0,
                            control_rate_hz: float = CONTROL_RATE_HZ,
                            settle_s: float = 30.0,
                            f_hz: np.ndarray | None = None,
                            params: dict[str, float] | None = None) -> si.Reflection:
    """|r| of the drive with ``controller`` (its ``params`` overriding the defaults) in the
    loop (``mode``: speed or torque), after ``settle_s`` off bottom for the controller to
    come to rest; no analytic curve (the controller is a sampled, filtered law)."""
    f_hz = si.reflection_frequencies() if f_hz is None else f_hz
    ratio = complex_reflection_with(preset_name, controller, f_hz, mode, seconds,
                                    control_rate_hz, settle_s, params)
    return si.Reflection([float(f) for f in f_hz], [float(r) for r in np.abs(ratio)], None)


def complex_reflection_with(preset_name: str, controller: str, f_hz: np.ndarray,
                            mode: str = "speed", seconds: float = 120.0,
                            control_rate_hz: float = CONTROL_RATE_HZ,
                            settle_s: float = 30.0,
                            params: dict[str, float] | None = None) -> np.ndarray:
    """A(f) / B(f) at the top with ``controller`` in the loop (as
    :func:`measure_reflection_with`), complex: a = T + Z w leaving, b = T - Z w arriving."""
    preset = load_preset(preset_name)
    si.require_distributed(preset)
    scenario = Scenario(preset=preset_name, controller=controller, mode=mode,
                        duration_s=settle_s + seconds, enable_at_s=0.0,
                        control_rate_hz=control_rate_hz, params=dict(params or {}))
    settle = round(settle_s * control_rate_hz)
    return si.reflection_of(
        lambda pulse: _top_waves_through_bench(scenario, preset, pulse, settle),
        control_rate_hz, np.asarray(f_hz, dtype=float), with_phase=True)
