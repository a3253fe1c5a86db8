"""Controllers by name: the references of :mod:`~drill_sim_ros.control.controllers`, or a
user's class as ``module:Class`` (ROS-free)."""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

from drill_sim_ros.control.controllers import SoftTorque, Stiff, TopDriveController, ZTorque
from drill_sim_ros.model.errors import ParameterError


class NoControl(Stiff):
    """The rig as delivered: the drive's own speed loop on the operator's setpoint."""

    name = "none"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.mode != "speed":
            raise ParameterError("controller 'none' is the drive's own speed loop: use "
                                 "--mode speed (in torque mode a controller must close the "
                                 "loop, e.g. stiff)")


BUILTIN: dict[str, type[TopDriveController]] = {
    cls.name: cls for cls in (NoControl, Stiff, SoftTorque, ZTorque)}


def controller_class(name: str) -> type:
    """The class of ``name``: a built-in (none, stiff, soft_torque, z_torque) or
    ``package.module:Class`` importable from the working directory or ``PYTHONPATH``, or
    ``path/to/file.py:Class``; ParameterError naming the choices otherwise."""
    if name in BUILTIN:
        return BUILTIN[name]
    module_name, sep, class_name = name.rpartition(":")
    if not sep or not module_name or not class_name:
        raise ParameterError(f"controller {name!r} is not one of {sorted(BUILTIN)} nor of "
                             "the form package.module:Class or path/to/file.py:Class")
    module = _module_of_file(name, module_name) if module_name.endswith(".py") else \
        _module_named(name, module_name)
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        raise ParameterError(f"controller {name!r}: {module_name!r} has no class "
                             f"{class_name!r}")
    return cls


def _module_named(name: str, module_name: str) -> ModuleType:
    if os.getcwd() not in sys.path:          # a user's module in the working directory
        sys.path.append(os.getcwd())
    try:
        return importlib.import_module(module_name)
    except ImportError as exc:
        raise ParameterError(f"controller {name!r}: cannot import {module_name!r} ({exc})"
                             ) from exc
    except Exception as exc:  # (the user's module failed as it loaded)
        raise ParameterError(f"controller {name!r}: importing {module_name!r} raised "
                             f"{type(exc).__name__}: {exc}") from None


def _module_of_file(name: str, file_name: str) -> ModuleType:
    """The module of a Python file (``path/to/file.py:Class``), loaded once per path."""
    path = Path(file_name).resolve()
    if not path.is_file():
        raise ParameterError(f"controller {name!r}: no such file {file_name}")
    module_name = "drill_sim_user_controller_" + hashlib.sha1(str(path).encode()).hexdigest()[:12]
    if module_name in sys.modules:
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # (the user's file failed as it loaded)
        del sys.modules[module_name]
        raise ParameterError(f"controller {name!r}: loading {file_name} raised "
                             f"{type(exc).__name__}: {exc}") from None
    return module


def make_controller(name: str, **kwargs: Any) -> Any:
    """An instance of :func:`controller_class` ``(name)`` built with ``kwargs`` (rig,
    schedule, mode, period_s, enable_at_s and its own parameters); it must have
    ``reset()`` and ``update(measurement) -> Command``."""
    cls = controller_class(name)
    try:
        controller = cls(**kwargs)
    except TypeError as exc:
        raise ParameterError(f"controller {name!r} cannot be built: {exc}") from exc
    for method in ("reset", "update"):
        if not callable(getattr(controller, method, None)):
            raise ParameterError(f"controller {name!r} has no {method}() method")
    return controller


def display_name(name: str) -> str:
    """What tables call controller ``name``: its class's ``name`` attribute (what its
    errors say), or its class name when it keeps the base class's ``base``."""
    cls = controller_class(name)
    label = getattr(cls, "name", None)
    return label if isinstance(label, str) and label and label != TopDriveController.name \
        else cls.__name__
