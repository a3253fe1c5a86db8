"""The rig's physics a controller is tuned from (SI, ROS-free).

From a physical preset (RGD07 eq. 1 and the top drive of ``model.top_drive``):

* C, the torsional stiffness of the drill pipe, G J_p / L (N m/rad) (of a distributed
  string: its lumped equivalent, string.lumped_equivalent);
* I, the lumped inertia of eq. 1: BHA + a third of the pipe (kg m^2);
* J, the top drive's inertia referred to the quill (kg m^2);
* Z = J_p sqrt(G rho), the torsional characteristic impedance of the drill pipe (of a
  distributed string: of its top section, the one the drive meets) (N m s/rad):
  the torque a torsional wave carries per unit of angular speed, so a top end that turns at
  -T/Z absorbs an arriving wave without reflection (the principle of the impedance-matching
  soft-torque systems, Dwars 2015, SPE/IADC-173037-MS);
* omega_1 = sqrt(C/I) = 1/t*, the string's first torsional mode on a fixed top (eq. 19);
* the first three torsional natural frequencies of the string as sections (fixed top, free
  bit with its lumped inertia; ``string.analytic_modes_hz``; of a lumped preset: of the
  two sections its ``pipe_*`` / ``bha_*`` keys describe), and the scorecard's cut-off
  between stick-slip and the collars' ringing, twice the third (:func:`analysis.cutoff_of`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from drill_sim_ros.control.command import quantity
from drill_sim_ros.model.analysis import MODE_COUNT, cutoff_of
from drill_sim_ros.model.defaults import MAX_SURFACE_RPM
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import PhysicalParams, structure
from drill_sim_ros.model.presets import Preset, string_from_dict
from drill_sim_ros.model.string import StringSpec, analytic_modes_hz


@dataclass(frozen=True)
class RigPhysics:
    """What the tuning rules use, SI: the ``rig`` a controller is built with."""

    stiffness_nm_rad: float = quantity(
        "N m/rad", "C, the drill pipe's torsional stiffness G J_p / L (of a distributed "
        "string: its lumped equivalent)")
    bit_inertia_kg_m2: float = quantity(
        "kg m^2", "I, the lumped inertia of RGD07 eq. 1: BHA + a third of the pipe")
    drive_inertia_kg_m2: float = quantity(
        "kg m^2", "J, the top drive's inertia referred to the quill")
    impedance_nm_s: float = quantity(
        "N m s/rad", "Z = J_p sqrt(G rho), the torsional characteristic impedance of the "
        "(top section's) drill pipe: a top that turns at -T/Z absorbs an arriving wave")
    max_torque_nm: float = quantity(
        "N m", "the drive's motor torque limit (inf: none)")
    drive_kp_nm_s: float = quantity(
        "N m s/rad", "the drive's own PI speed loop (speed mode): proportional gain")
    drive_ki_nm: float = quantity(
        "N m/rad", "the drive's own PI speed loop (speed mode): integral gain")
    bit_area_m2: float = quantity("m^2", "pi a^2, the bit's area (for the specific energy)")
    torsional_modes_hz: tuple[float, ...] = quantity(
        "Hz", "the string's first torsional natural frequencies, fixed top and free bit, "
        "lowest first (``string.analytic_modes_hz``)")
    cutoff_hz: float = quantity(
        "Hz", "the scorecard's cut-off: stick-slip below, the collars' ringing above "
        "(twice the third mode)")
    max_surface_rpm: float = quantity(
        "rev/min", "the speed setpoint's limit (sim_node's limits.max_surface_rpm)",
        MAX_SURFACE_RPM)
    motor_lag_s: float = quantity(
        "s", "the time constant with which the drive's motor torque follows its command "
        "(0: at once)", 0.0)

    @property
    def first_mode_rad_s(self) -> float:
        """omega_1 = sqrt(C / I) [rad/s], the torsional mode of the bit on the pipe (RGD07
        eq. 19: 1/t*)."""
        return math.sqrt(self.stiffness_nm_rad / self.bit_inertia_kg_m2)


def rig_physics(preset: Preset) -> RigPhysics:
    """The physics of a physical preset; ParameterError for a dimensionless one."""
    phys = preset.physical
    if phys is None:
        raise ParameterError(f"preset '{preset.name}' is dimensionless; the controllers are "
                             "tuned in SI and need a physical preset (e.g. field_8p5in_shale)")
    s = structure(phys, preset.string)
    if preset.string.sections:                  # Z of the top section: what the drive meets
        impedance = preset.string.sections[0].torsional_impedance_nm_s
    else:
        pipe_polar_m4 = 0.5 * math.pi * (phys.pipe_outer_radius_m**4
                                         - phys.pipe_inner_radius_m**4)
        impedance = pipe_polar_m4 * math.sqrt(phys.shear_modulus_pa * phys.density_kg_m3)
    drive = preset.drive
    modes_hz = tuple(analytic_modes_hz(sections_of(preset.string, phys), MODE_COUNT))
    return RigPhysics(
        stiffness_nm_rad=s.stiffness_nm_per_rad, bit_inertia_kg_m2=s.inertia_kg_m2,
        drive_inertia_kg_m2=drive.inertia_kg_m2, impedance_nm_s=impedance,
        max_torque_nm=drive.max_torque_nm, drive_kp_nm_s=drive.kp_nm_s,
        drive_ki_nm=drive.ki_nm, motor_lag_s=drive.motor_lag_s,
        bit_area_m2=math.pi * phys.bit_radius_m**2,
        torsional_modes_hz=modes_hz, cutoff_hz=cutoff_of(modes_hz))


def sections_of(string: StringSpec, phys: PhysicalParams) -> StringSpec:
    """A physical preset's string as sections: its own when distributed, else the
    two-section shorthand of its ``pipe_*`` / ``bha_*`` keys (``presets.string_from_dict``,
    the one reading of them)."""
    if string.distributed:
        return string
    return string_from_dict({"model": "distributed"}, phys)
