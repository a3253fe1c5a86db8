"""Entity paths of the dashboard, the timeline, and how telemetry maps onto the views.

Shared by the logging functions, the blueprint and the tests: one place names every path.
"""

from __future__ import annotations

from drill_sim_ros.topics import MODE_NAMES

APP_ID = "drill_sim_ros"
TIMELINE = "sim_time"          # duration timeline, seconds of simulated time

# ---- time series (display units in the names) -----------------------------------------
WOB_BIT = "/timeseries/wob/bit"                  # kN
WOB_APPLIED = "/timeseries/wob/applied"          # kN
WOB_OFF_BOTTOM = "/timeseries/wob/off_bottom"    # kN, markers at off-bottom samples only
TORQUE_BIT = "/timeseries/torque/bit"            # kN m
TORQUE_SURFACE = "/timeseries/torque/surface"    # kN m
ROP = "/timeseries/rop/bit"                      # m/h
RPM_BIT = "/timeseries/rpm/bit"                  # rev/min
RPM_SURFACE = "/timeseries/rpm/surface"          # rev/min
RPM_BHA = "/timeseries/rpm/bha"                  # rev/min, bottom of the string
RPM_STICK = "/timeseries/rpm/stick"              # rev/min, markers at stuck samples only
MODE = "/timeseries/mode/mode"                   # 0 cutting .. 3 off_bottom (MODE_NAMES)

# (path, telemetry field, factor SI -> display unit, legend name)
SCALAR_SERIES: tuple[tuple[str, str, float, str], ...] = (
    (WOB_BIT, "wob_n", 1e-3, "WOB [kN]"),
    (WOB_APPLIED, "applied_wob_n", 1e-3, "applied WOB [kN]"),
    (TORQUE_BIT, "tob_nm", 1e-3, "TOB [kN m]"),
    (TORQUE_SURFACE, "surface_torque_nm", 1e-3, "surface torque [kN m]"),
    (ROP, "rop_m_s", 3600.0, "ROP [m/h]"),
    (RPM_BIT, "bit_rpm", 1.0, "bit [rpm]"),
    (RPM_BHA, "bha_rpm", 1.0, "BHA [rpm]"),
    (RPM_SURFACE, "surface_rpm", 1.0, "surface [rpm]"),
    (MODE, "mode", 1.0, "mode: " + ", ".join(f"{i} {n}" for i, n in enumerate(MODE_NAMES))),
)
# (path, telemetry field, factor, mode marked, legend name)
PHASE_MARKERS: tuple[tuple[str, str, float, int, str], ...] = (
    (RPM_STICK, "bit_rpm", 1.0, 2, "stick"),
    (WOB_OFF_BOTTOM, "wob_n", 1e-3, 3, "off bottom"),
)

# ---- 2D views (stored positions: Frame2D.stored, i.e. scaled per axis, y negated) ------
PHASE_PORTRAIT = "/phase_portrait"
PHASE_TRAJECTORY = "/phase_portrait/trajectory"  # segments to (v/v0, omega/omega0), Fig. 5
PHASE_REFERENCE = "/phase_portrait/reference"
BOTTOM_HOLE = "/bottom_hole"
BOTTOM_HOLE_LAST = "/bottom_hole/last_turn"      # r = max(delta, 0)/delta0 at bit angle, Fig. 7
BOTTOM_HOLE_PREVIOUS = "/bottom_hole/previous_turn"
BOTTOM_HOLE_REFERENCE = "/bottom_hole/reference"
ES_DIAGRAM = "/es_diagram"
ES_RUNNING = "/es_diagram/running_average"        # segments to (S, E), eq. 48, Fig. 12
ES_FRICTION_LINE = "/es_diagram/friction_line"    # eq. 50
ES_POINTS = "/es_diagram/reference_points"        # cutting point and trivial solution
ES_REFERENCE = "/es_diagram/reference"            # axes, ticks

# ---- severity ----------------------------------------------------------------------------
SEVERITY = "/severity"
SSI = "/severity/ssi"
STICK_FRACTION = "/severity/stick_fraction"
INFO = "/info"

# ---- the distributed string (drill/string/torsion; viz.string_views) --------------------
STRING_DEPTH_TIME = "/string/depth_time"         # the depth x time view's origin
STRING_PICTURE = "/string/depth_time/picture"    # RGB image: depth (rows) x profiles (columns)
STRING_OUTLINE = "/string/depth_time/outline"
STRING_DEPTH_AXIS = "/string/depth_time/depth_axis"      # depth tick labels m, title
STRING_TIME_AXIS = "/string/depth_time/time_axis"        # s before the newest profile
STRING_COLOUR_BAR = "/string/depth_time/colour_bar"      # RGB image of the palette
STRING_SCALE_LABELS = "/string/depth_time/scale_labels"  # the colour bar's rpm, title
STRING_SPEED = "/string/speed"                   # bar chart: rpm over depth m
STRING_TORQUE = "/string/torque"                 # bar chart: kN m over depth m

# Every path that carries one row per telemetry sample.
PER_SAMPLE = (*(s[0] for s in SCALAR_SERIES), PHASE_TRAJECTORY, SSI, STICK_FRACTION)

MODE_COLORS = ((31, 119, 180), (255, 127, 14), (214, 39, 40), (148, 103, 189))
"""RGB per mode: cutting blue, lost contact orange, stuck red, off bottom purple."""
MODE_COLOR_NAMES = ("blue", "orange", "red", "purple")
