"""Write the generated tables of the docs from the code's own tables (`make docs`).

Each generated region of a page sits between two markers,
``<!-- BEGIN GENERATED: NAME (make docs) -->`` and ``<!-- END GENERATED: NAME -->``; the
script rewrites what lies between them and nothing else. ``--check`` writes nothing and
exits 1 when a page differs from what the script would write (tests/test_docs.py does the
same).

Sources: ``SPECS`` of ``drill_sim_ros/ros/parameters.py`` (the parameter table) and
``MSG_TYPES``, ``DESCRIPTIONS``, ``JOINTS`` and ``JOINT_FIELDS`` of ``drill_sim_ros/topics.py``
with the QoS sim_node uses (the topic table); ``VARIABLES`` of
``drill_sim_ros/hil/address_space.py`` (the OPC UA address space of docs/hil.md) and
``SETTINGS`` of ``drill_sim_ros/ros/opcua_gateway.py`` (the gateway's parameters there);
the controller API of docs/closed-loop.md from the field metadata (unit, meaning) of
``Command``, ``SurfaceMeasurement`` and ``RigPhysics``, the signatures and docstrings of
``TopDriveController.HOOKS`` and ``LowPass``, and the source of ``examples/soft_speed_pi.py``.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
BEGIN = "<!-- BEGIN GENERATED: {name} (make docs) -->"
END = "<!-- END GENERATED: {name} -->"
UNIT_IN_TEXT = re.compile(r"\[([^\]]+)\]")
# The unit a parameter's name ends in, when its description names none; checked in order,
# so a suffix comes before any shorter one it ends in (_rad_s before _s).
UNIT_SUFFIXES = (("_rad_s", "rad/s"), ("_kg_m2", "kg m^2"), ("_nm", "N m"), ("_hz", "Hz"),
                 ("_mb", "MB"), ("_rpm", "rev/min"), ("_seconds", "s"), ("_periods", "periods"),
                 ("_n", "N"), ("_s", "s"))


def _number(value: float) -> str:
    """A default or a bound as a reader writes it: 60000, 0.001, 1e+09."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        return str(value)              # inf, -inf, nan
    if value == int(value) and abs(value) < 1e7:
        return str(int(value))
    return f"{value:.6g}"


def _value(value: Any) -> str:
    if isinstance(value, str):
        return f'"{value}"' if value == "" else value
    if isinstance(value, (bool, int, float)):
        return _number(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return str(value)


def unit_of(spec: Any) -> str:
    """The spec's own unit if it has one, else the unit its description names in square
    brackets, else the one its name ends in (``publish_rate_hz``: Hz), else "–"."""
    own = getattr(spec, "unit", None)
    if own is not None:
        return own
    name, description = spec.name, spec.description
    found = UNIT_IN_TEXT.search(description)
    if found:
        return found.group(1)
    return next((unit for suffix, unit in UNIT_SUFFIXES if name.endswith(suffix)), "–")


def _range(spec: Any) -> str:
    if spec.choices:
        return ", ".join(spec.choices)
    if spec.low is not None and spec.high is not None:
        return f"{_number(spec.low)} … {_number(spec.high)}"
    return "true, false" if spec.kind == "bool" else "any"


def _default(spec: Any, preset: Any) -> str:
    value = _value(spec.default_for(preset))
    return f"preset's ({value})" if callable(spec.default) else value


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def parameter_table() -> str:
    """One row per sim_node parameter, in the order of ``SPECS``."""
    from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
    from drill_sim_ros.ros.parameters import SPECS

    preset = load_preset(DEFAULT_PRESET)
    rows = ["| name | type | unit | range | default | runtime | meaning |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    for spec in SPECS:
        cells = (f"`{spec.name}`", spec.kind, unit_of(spec), _range(spec),
                 _default(spec, preset), "no" if spec.read_only else "yes",
                 spec.description)
        rows.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(rows)


def _qos_text(profile: Any) -> str:
    durability = profile.durability.name.lower().replace("_", " ")
    history = "keep-all" if profile.history.name == "KEEP_ALL" else f"keep-last {profile.depth}"
    return f"{profile.reliability.name.lower()}, {durability}, {history}"


def _content(topic: str) -> str:
    """The topic's description, then what each joint's position, velocity, effort mean."""
    from drill_sim_ros import topics

    text = topics.DESCRIPTIONS[topic]
    if topic not in topics.JOINTS:
        return text
    fields = topics.JOINT_FIELDS.get(topic, {})
    joints = topics.JOINTS[topic]
    if tuple(fields) != joints:
        raise ValueError(f"topics.JOINT_FIELDS[{topic}] describes {tuple(fields)}, "
                         f"the topic carries {joints}")
    return text + ": " + "; ".join(f"`{j}` [{', '.join(fields[j])}]" for j in joints)


def topic_table() -> str:
    """One row per topic of ``topics.MSG_TYPES``: direction, type, QoS, content."""
    from drill_sim_ros import topics
    from drill_sim_ros.ros.sim_node import COMMAND_QOS, topic_qos

    missing = [t for t in topics.MSG_TYPES if t not in topics.DESCRIPTIONS]
    if missing:
        raise ValueError(f"topics.DESCRIPTIONS has no entry for {', '.join(missing)}")
    rows = ["| topic | sim_node | type | QoS | content, unit |",
            "| --- | --- | --- | --- | --- |"]
    for topic, msg_type in topics.MSG_TYPES.items():
        subscribed = topic in topics.COMMANDS
        qos = COMMAND_QOS if subscribed else topic_qos(topic)
        cells = (f"`{topic}`", "subscribes" if subscribed else "publishes",
                 msg_type.replace("/msg/", "/"), _qos_text(qos), _content(topic))
        rows.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(rows)


def address_space_table() -> str:
    """The OPC UA gateway's address space (``VARIABLES`` of hil/address_space.py)."""
    from drill_sim_ros.hil.address_space import markdown_table
    return markdown_table()


def gateway_parameter_table() -> str:
    """The OPC UA gateway's own parameters (``SETTINGS`` of ros/opcua_gateway.py)."""
    from drill_sim_ros.ros.opcua_gateway import settings_table
    return settings_table()


# The controller API that docs/closed-loop.md documents: (module, names); a controller written
# from the page imports only these (tests/control/test_controller_api.py checks the example).
CONTROLLER_API: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("drill_sim_ros.control.command", ("Command", "SurfaceMeasurement")),
    ("drill_sim_ros.control.rig", ("RigPhysics",)),
    ("drill_sim_ros.control.controllers", ("LowPass", "TopDriveController")),
    ("drill_sim_ros.model.errors", ("ParameterError",)),
)
CONTROLLER_EXAMPLE = "examples/soft_speed_pi.py"
_RST_ROLE = re.compile(r":(?:meth|func|class|mod|attr):`~?(?:[\w.]*\.)?(\w+)`")


def _markdown_of_doc(text: str) -> str:
    """A docstring as one line of Markdown: ``x`` -> `x`, :meth:`a.b` -> `b`."""
    text = _RST_ROLE.sub(r"`\1`", " ".join(text.split()))
    return text.replace("``", "`")


def _field_rows(cls: type) -> list[str]:
    """One row per field of a dataclass whose fields carry ``unit`` and ``meaning``."""
    import dataclasses

    rows = ["| field | unit | meaning |", "| --- | --- | --- |"]
    for f in dataclasses.fields(cls):
        if "unit" not in f.metadata or "meaning" not in f.metadata:
            raise ValueError(f"{cls.__name__}.{f.name} has no unit and meaning (quantity())")
        default = "" if f.default is dataclasses.MISSING else \
            f" (default {_value(f.default)})"
        rows.append("| " + " | ".join(_cell(c) for c in (
            f"`{f.name}`", f.metadata["unit"], _markdown_of_doc(f.metadata["meaning"])
            + default)) + " |")
    return rows


def _property_rows(cls: type) -> list[str]:
    """One row per property, its unit in square brackets in its docstring."""
    rows = []
    for name, member in vars(cls).items():
        if not isinstance(member, property):
            continue
        doc = _markdown_of_doc(member.__doc__ or "")
        found = UNIT_IN_TEXT.search(doc)
        if not found:
            raise ValueError(f"{cls.__name__}.{name}'s docstring names no [unit]")
        meaning = (doc[:found.start()].rstrip() + doc[found.end():]).strip()
        rows.append("| " + " | ".join(_cell(c) for c in (
            f"`{name}` (property)", found.group(1), meaning)) + " |")
    return rows


def _method_rows(cls: type, names: tuple[str, ...]) -> list[str]:
    import inspect

    rows = ["| method | what it does, when it is called |", "| --- | --- |"]
    for name in names:
        method = getattr(cls, name)
        signature = str(inspect.signature(method)).replace("'", "")
        rows.append("| " + " | ".join(_cell(c) for c in (
            f"`{name}{signature}`", _markdown_of_doc(inspect.getdoc(method) or ""))) + " |")
    return rows


def controller_api() -> str:
    """The controller API's reference: imports, the classes' fields with their units, the
    rig's properties, the base class's hooks and LowPass."""
    import inspect

    from drill_sim_ros.control.command import Command, SurfaceMeasurement
    from drill_sim_ros.control.controllers import LowPass, TopDriveController
    from drill_sim_ros.control.rig import RigPhysics

    imports = "\n".join(f"from {module} import {', '.join(names)}"
                        for module, names in CONTROLLER_API)
    parts = ["```python", imports, "```", ""]
    for cls, what in ((SurfaceMeasurement, "what `update` gets each period"),
                      (Command, "what `update` returns"),
                      (RigPhysics, "`self.rig`, the rig's physics, SI")):
        rows = _field_rows(cls) + _property_rows(cls)
        parts += [f"**`{cls.__name__}`**, {what}: {_markdown_of_doc(cls.__doc__ or '')}",
                  "", *rows, ""]
    base = TopDriveController
    parts += [f"**`{base.__name__}`**: {_markdown_of_doc(inspect.getdoc(base) or '')}", "",
              *_method_rows(base, base.HOOKS), ""]
    signature = str(inspect.signature(LowPass)).replace("'", "")
    parts += [f"**`LowPass{signature}`**: {_markdown_of_doc(inspect.getdoc(LowPass) or '')}"]
    return "\n".join(parts)


def controller_example() -> str:
    """The worked example's source, as a Python block."""
    source = (ROOT / CONTROLLER_EXAMPLE).read_text(encoding="utf-8").rstrip("\n")
    return f"`{CONTROLLER_EXAMPLE}`:\n\n```python\n{source}\n```"


# (page, region name) -> the function that writes the region
REGIONS: dict[tuple[str, str], Callable[[], str]] = {
    ("docs/sim_node.md", "topics"): topic_table,
    ("docs/sim_node.md", "parameters"): parameter_table,
    ("docs/hil.md", "gateway-parameters"): gateway_parameter_table,
    ("docs/hil.md", "address-space"): address_space_table,
    ("docs/closed-loop.md", "controller-api"): controller_api,
    ("docs/closed-loop.md", "controller-example"): controller_example,
}


def fill(text: str, name: str, body: str) -> str:
    """``text`` with the region ``name`` holding ``body``; ValueError if it has no region."""
    begin, end = BEGIN.format(name=name), END.format(name=name)
    start, stop = text.find(begin), text.find(end)
    if start < 0 or stop < start:
        raise ValueError(f"no region '{begin}' ... '{end}'")
    return text[:start + len(begin)] + "\n" + body + "\n" + text[stop:]


def expected_pages(root: Path = ROOT) -> dict[Path, str]:
    """Every page with generated regions, as the script writes it."""
    pages: dict[Path, str] = {}
    for (page, name), make in REGIONS.items():
        path = root / page
        text = pages.get(path) or path.read_text(encoding="utf-8")
        pages[path] = fill(text, name, make())
    return pages


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a page differs from what it would be")
    args = parser.parse_args(argv)
    try:
        pages = expected_pages()
    except ValueError as exc:
        print(f"docs/generate.py: {exc}", file=sys.stderr)
        return 2
    stale = []
    for path, text in pages.items():
        if path.read_text(encoding="utf-8") == text:
            continue
        stale.append(path.relative_to(ROOT))
        if not args.check:
            path.write_text(text, encoding="utf-8")
    verb = "out of date (run `make docs`)" if args.check else "rewritten"
    for path in stale:
        print(f"{path}: {verb}")
    return 1 if args.check and stale else 0


if __name__ == "__main__":
    sys.exit(main())
