"""Rock layers by depth: the bit-rock law's parameters change where the bit crosses a layer top.

ROS-free. A layer sets, from its top down, the rock's intrinsic specific energy eps (eq. 2,
4), the bit-rock friction mu gamma (eq. 5, so beta = mu gamma zeta, eq. 10) and the wearflat
contact sigma l (eq. 11, so lambda). The kernel's units stay those of the preset's reference
rock (L* = 2 C / (eps_ref a^2), force unit zeta eps_ref a L*, eq. 19-20), so in a layer:

    W_c = (eps / eps_ref) delta,   T_c = (eps / eps_ref) delta        (eq. 4, scaled)
    beta = mu gamma zeta,          lambda = sigma l / (zeta eps_ref L*)  (eqs. 10, 24)

The kernel stops after the step at which the bit reaches the next layer's top
(``kernel.STATUS_LAYER``); the simulator applies the layer and goes on in the same call.
Depths are of the bit below where the run started, in m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from drill_sim_ros.model.checks import as_number, check_known_keys, shown
from drill_sim_ros.model.errors import ParameterError

LAYER_KEYS = ("top_m", "intrinsic_specific_energy_pa", "mu_gamma",
              "contact_stress_times_wearflat_n_per_m")


@dataclass(frozen=True)
class Layer:
    """One layer in kernel terms: its top (in L*), the cutting factor eps / eps_ref, beta
    and lambda."""

    top: float
    cut_factor: float
    beta: float
    lam: float


@dataclass(frozen=True)
class Rock:
    """The preset's reference rock and bit: what a layer's SI values are scaled against."""

    eps_pa: float
    zeta: float
    mu_gamma: float
    sigma_l_n_per_m: float
    length_m: float                          # L*


def _value(i: int, layer: dict[str, Any], key: str, default: float, low: float,
           high: float) -> float:
    value = layer.get(key, default)
    number = as_number(value)
    x = math.nan if number is None else number
    if not (math.isfinite(x) and low <= x <= high):
        raise ParameterError(f"formation[{i}].{key} = {shown(value)} must be a number in "
                             f"[{low:g}, {high:g}]")
    return x


def layers_from_dicts(layers: Any, rock: Rock) -> tuple[Layer, ...]:
    """Scenario or parameter ``formation`` entries (SI keys ``LAYER_KEYS``; a missing rock
    key keeps the preset's value) -> layers sorted by top; one-line errors name the entry."""
    if not isinstance(layers, (list, tuple)):
        raise ParameterError("formation must be a list of layers {top_m, ...}")
    out = []
    for i, layer in enumerate(layers):
        if not isinstance(layer, dict):
            raise ParameterError(f"formation[{i}] must be a mapping of {', '.join(LAYER_KEYS)}")
        check_known_keys(layer, LAYER_KEYS, f"formation[{i}]")
        if "top_m" not in layer:
            raise ParameterError(f"formation[{i}] needs top_m (depth below the start, m)")
        top = _value(i, layer, "top_m", 0.0, 0.0, 1e5)
        eps = _value(i, layer, "intrinsic_specific_energy_pa", rock.eps_pa, 1e3, 1e12)
        mu_gamma = _value(i, layer, "mu_gamma", rock.mu_gamma, 0.0, 10.0)
        sigma_l = _value(i, layer, "contact_stress_times_wearflat_n_per_m",
                         rock.sigma_l_n_per_m, 0.0, 1e12)
        out.append(Layer(top=top / rock.length_m, cut_factor=eps / rock.eps_pa,
                         beta=mu_gamma * rock.zeta,
                         lam=sigma_l / (rock.zeta * rock.eps_pa * rock.length_m)))
    return tuple(sorted(out, key=lambda x: x.top))
