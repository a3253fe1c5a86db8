"""Predict whether the first torsional mode grows, per controller (``drill_sim stability``).

ROS-free. The loop of the pipe's first mode (docs/string.md, "Predicting the first mode's
growth"): a torque wave goes down the pipe, the BHA and bit reflect it with r_bit, it comes
back up, the top reflects it with r_top. It grows when the loop gain

    G = |r_bit(f1)| |r_top(f1)| |exp(-2 gamma L_pipe)|

exceeds 1 at the first mode's frequency f1, where the loop's phase is a whole turn.

* r_bit: ANALYTIC, not measured (:mod:`drill_sim_ros.model.bit_reflection`): the collars as
  lossy lines ending in the bit's inertia and the bit law's small-signal slope
  b = -dT/dw at the operating point with the law's lag, b / (1 + s tau). The slope is a
  central difference of the law's own torque at the steady drilling state
  (:func:`analysis.trivial_solution` at the point's rpm and WOB).
* r_top: MEASURED in the time domain with the controller in the loop, complex
  (:func:`reflection.complex_reflection_with`, A / B at the top: +1 for a clamped top),
  once per controller on a band up to three times the string's first mode, interpolated.
* Where the slope beats what the pipe and the collars absorb (b > about Z of the pipe),
  the bit is unstable by itself on an endless pipe, whatever comes back from the top
  (:func:`bit_reflection.runs_away`): then G is infinite, growth under every controller.
* f1: the lowest frequency at which the loop r_top r_bit exp(-2 gamma L_pipe) is real and
  positive (:func:`bit_reflection.first_crossing_hz`) with that controller's top: a soft
  top moves the mode (down, where it reflects more), and G is read there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.control.reflection import complex_reflection_with
from drill_sim_ros.model import analysis
from drill_sim_ros.model import bit_reflection as br
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import string_instruments as si
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import Preset, load_preset

CONTROLLERS = ("stiff", "soft_torque", "z_torque")
RPM_RANGE = (1.0, 400.0)          # surface rpm a prediction accepts
WOB_RANGE_N = (1.0e3, 1.0e6)      # applied WOB, N
BAND_LOW_HZ = 0.01                # r_top is measured from here
MODE_SEARCH = 3.0                 # to this x the clamped-top first mode (f1 searched there)
BAND_POINTS = 240


@dataclass(frozen=True)
class Prediction:
    """The first mode's loop at one operating point under one controller."""

    controller: str
    rpm: float
    wob_n: float
    slope_nm_s: float          # b = -dT/dw of the bit law at the point
    mode_hz: float             # f1 with the controller's top and the bit's termination
    r_bit: float               # |r_bit(f1)|
    r_top: float               # |r_top(f1)|, measured with the controller
    pipe: float                # |exp(-2 gamma L_pipe)| at f1: the pipe's round trip
    loop_gain: float
    runs_away: bool = False    # the bit unstable by itself (G infinite, mode undefined)

    @property
    def grows(self) -> bool:
        return self.loop_gain > 1.0

    def as_dict(self) -> dict[str, object]:
        """JSON-ready; a figure that is not finite (a bit that runs away) is null."""
        def num(value: float, digits: int) -> float | None:
            return round(value, digits) if math.isfinite(value) else None

        return {"controller": self.controller, "rpm": self.rpm, "wob_n": self.wob_n,
                "slope_nm_s": num(self.slope_nm_s, 3), "mode_hz": num(self.mode_hz, 5),
                "r_bit": num(self.r_bit, 4), "r_top": num(self.r_top, 4),
                "pipe_round_trip": num(self.pipe, 4), "loop_gain": num(self.loop_gain, 4),
                "runs_away": self.runs_away, "grows": self.grows}


def check_point(rpm: float, wob_n: float) -> None:
    """One-line errors for an operating point out of range."""
    if not (math.isfinite(rpm) and RPM_RANGE[0] <= rpm <= RPM_RANGE[1]):
        raise ParameterError(f"--rpm = {rpm!r} must be in [{RPM_RANGE[0]:g}, "
                             f"{RPM_RANGE[1]:g}]")
    if not (math.isfinite(wob_n) and WOB_RANGE_N[0] <= wob_n <= WOB_RANGE_N[1]):
        raise ParameterError(f"--wob-n = {wob_n!r} must be in [{WOB_RANGE_N[0]:g}, "
                             f"{WOB_RANGE_N[1]:g}] N")


def checked_preset(name: str) -> Preset:
    preset = load_preset(name)
    if not preset.is_physical:
        raise ParameterError(f"preset '{preset.name}' is dimensionless; stability needs a "
                             "physical preset with a distributed string")
    si.require_distributed(preset)
    return preset


def operating_point(preset: Preset) -> tuple[float, float]:
    """The preset's own (surface rpm, applied WOB N)."""
    p, sc = preset.params, preset.scales
    return sc.rpm(p.omega0), sc.wob_n(p.w0)


def bit_slope_nm_s(preset: Preset, rpm: float, wob_n: float) -> float:
    """b = -dT/dw of the preset's bit law in steady drilling at ``rpm`` and ``wob_n``."""
    sc = preset.scales
    p = preset.params.with_(omega0=sc.omega_from_rpm(rpm), w0=sc.w_from_newton(wob_n))
    steady = analysis.trivial_solution(p)
    return br.law_slope_nm_s(preset.bit_law, steady.depth_of_cut, steady.wearflat, p.beta,
                             p.omega0, sc.torque_nm, sc.time_s)


def response_s(preset: Preset) -> float:
    return preset.bit_law.response * preset.scales.time_s


def top_band_hz(preset: Preset) -> np.ndarray:
    """The frequencies on which r_top is measured and the first mode searched."""
    f1 = sg.analytic_modes_hz(preset.string, 1)[0]
    return np.linspace(BAND_LOW_HZ, MODE_SEARCH * f1, BAND_POINTS)


def measure_tops(preset_name: str, controllers: list[str]) -> dict[str, np.ndarray]:
    """r_top (complex) on :func:`top_band_hz` for each controller, measured in the time
    domain with the controller in the loop."""
    f_hz = top_band_hz(load_preset(preset_name))
    return {c: complex_reflection_with(preset_name, c, f_hz) for c in controllers}


def predict(preset: Preset, tops: dict[str, np.ndarray], rpm: float,
            wob_n: float) -> list[Prediction]:
    """The first mode's loop gain at ``rpm`` and ``wob_n`` for each controller of ``tops``
    (r_top on :func:`top_band_hz`): at the lowest frequency where the loop's phase is a
    whole turn with that top."""
    check_point(rpm, wob_n)
    slope, lag = bit_slope_nm_s(preset, rpm, wob_n), response_s(preset)
    band = top_band_hz(preset)
    if br.runs_away(preset.string, slope, lag, float(band[-1])):
        return [Prediction(name, rpm, wob_n, slope, math.nan, math.inf, math.nan, math.nan,
                           math.inf, runs_away=True) for name in tops]
    r_bit = br.bit_reflection(preset.string, slope, lag, band)
    pipe = br.pipe_round_trip(preset.string, band)
    out = []
    for name, r_top in tops.items():
        mode = br.first_crossing_hz(band, r_top * r_bit * pipe)
        if mode is None:
            raise ParameterError(f"no first mode below {band[-1]:.3g} Hz at {rpm:g} rpm and "
                                 f"{wob_n:g} N under {name} (bit slope {slope:.4g} N m s)")
        f = np.array([mode])
        bit = float(abs(br.bit_reflection(preset.string, slope, lag, f))[0])
        trip = float(abs(br.pipe_round_trip(preset.string, f))[0])
        top = float(abs(np.interp(mode, band, r_top.real)
                        + 1j * np.interp(mode, band, r_top.imag)))
        out.append(Prediction(name, rpm, wob_n, slope, mode, bit, top, trip,
                              bit * top * trip))
    return out
