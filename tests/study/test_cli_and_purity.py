"""User errors of the study commands and map-plot output (a core free of ROS:
tests/model/test_purity.py)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from drill_sim_ros.study import engine, store
from drill_sim_ros.study.regime import REGIME_COLORS, REGIME_NAMES
from tests.robust.helpers import run_cli
from tests.study.helpers import drill_sim, small_spec


def _one_line_error(result: subprocess.CompletedProcess[str], *words: str) -> None:
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    for word in words:
        assert word in lines[0], lines[0]


def test_bad_vary_name_names_the_allowed_ones(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--vary", "speed=1:2:3", "--out", str(tmp_path / "m.nc")),
                    "speed", "omega0", "w0_ratio")


def test_si_axis_needs_a_physical_preset(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--vary", "surface_rpm=40:80:3", "--out",
                              str(tmp_path / "m.nc")), "surface_rpm", "physical preset")


def test_two_weight_axes_refused(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--vary", "w0=7:8:2", "--vary", "w0_ratio=1.2:1.4:2",
                              "--out", str(tmp_path / "m.nc")), "w0", "w0_ratio")


def test_controller_needs_a_physical_preset(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--vary", "w0=7:8:2", "--controller", "soft_torque",
                              "--out", str(tmp_path / "m.nc")), "--controller",
                    "physical preset")


def test_controller_refuses_dimensionless_axes(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--params", "field_8p5in_shale_lumped", "--vary",
                              "psi=50:60:2",
                              "--controller", "soft_torque", "--out", str(tmp_path / "m.nc")),
                    "--controller", "psi", "surface_rpm")


def test_controller_unknown_name(tmp_path: Path) -> None:
    _one_line_error(drill_sim("map", "--params", "field_8p5in_shale_lumped", "--vary",
                              "surface_rpm=40:80:2", "--controller", "softer",
                              "--out", str(tmp_path / "m.nc")), "softer", "soft_torque")


def test_map_plot_draws_regimes_and_variables(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """The two plots in this process (cli.main), the two errors as a user meets them."""
    out = tmp_path / "map.nc"
    with engine.connect(workers=1) as client:
        engine.run_map(small_spec(), out, client)
    images = {}
    for var in ("regime", "kappa"):
        png = tmp_path / f"{var}.png"
        rc, _, err = run_cli(capsys, "map-plot", str(out), "-o", str(png), "--var", var)
        assert rc == 0, err
        images[var] = mpimg.imread(png)[..., :3]
        assert images[var].shape[0] > 300 and images[var].shape[1] > 400
    # Each regime the map holds fills its cells in its own colour (a cell is some 10^4
    # pixels; the legend's patch some 10^2), and a regime it does not hold is not drawn.
    codes = {int(c) for c in np.unique(store.load(out)["regime"].values)}
    assert len(codes) >= 2, codes  # beta either side of 1 (RGD07 Fig. 8a)
    for code, colour in enumerate(REGIME_COLORS):
        pixels = np.all(np.abs(images["regime"] - to_rgb(colour)) < 1.5 / 255, axis=-1).sum()
        assert (pixels > 5000) == (code in codes), (REGIME_NAMES[code], pixels)
    # The colour map follows the variable: the same map with kappa constant draws otherwise.
    flat = store.load(out)
    flat["kappa"] = flat["kappa"] * 0.0 + float(flat["kappa"].mean())
    store.save(flat, tmp_path / "flat.nc")
    rc, _, err = run_cli(capsys, "map-plot", str(tmp_path / "flat.nc"), "-o",
                         str(tmp_path / "flat.png"), "--var", "kappa")
    assert rc == 0, err
    changed = np.any(np.abs(mpimg.imread(tmp_path / "flat.png")[..., :3] - images["kappa"])
                     > 0.1, axis=-1)
    assert changed.mean() > 0.1, changed.mean()
    _one_line_error(drill_sim("map-plot", str(out), "--var", "nope"), "nope", "kappa")
    _one_line_error(drill_sim("map-plot", str(tmp_path / "missing.nc")), "missing.nc")


def test_dataset_attributes_hold_inputs_and_units(tmp_path: Path) -> None:
    ds = store.new_dataset(small_spec())
    assert ds.attrs["spec_json"] == small_spec().to_json()
    assert ds.attrs["tau_end"] == 60.0 and ds.attrs["dtau"] == 1e-4
    assert ds["w0_ratio"].attrs["units"] == "1"
    assert all("units" in ds[v].attrs for v in ds.data_vars)


def test_figures_renders_one_figure_and_names_unknown_ones(tmp_path: Path) -> None:
    result = drill_sim("figures", "-o", str(tmp_path), "--only", "fig8", "--workers", "1")
    assert result.returncode == 0, result.stderr
    image = mpimg.imread(tmp_path / "fig8.png")
    assert image.shape[0] > 400 and image.shape[1] > 600
    _one_line_error(drill_sim("figures", "-o", str(tmp_path), "--only", "fig99"), "fig99",
                    "fig11")
