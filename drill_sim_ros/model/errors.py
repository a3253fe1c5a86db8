"""Errors raised by the model core; all descend from :class:`DrillSimError`."""


class DrillSimError(Exception):
    """Base class of every error this package raises on purpose."""


class ParameterError(DrillSimError, ValueError):
    """A parameter is missing, unknown or outside its allowed range; the message names it."""


class NumericalFault(DrillSimError, FloatingPointError):
    """The integration produced a non-finite state; the simulator must be reset."""


class EnergyFault(NumericalFault):
    """The string created energy (the physics guard, Simulator._check_wall_energy); the
    message names the element, its depth and the time. The simulator must be reset."""


class HistoryOverflow(DrillSimError):
    """The exact-delay reference ran out of history storage (raise its capacity)."""
