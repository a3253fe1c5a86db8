"""Errors raised by the model core; all descend from :class:`DrillSimError`."""


class DrillSimError(Exception):
    """Base class of every error this package raises on purpose."""


class ParameterError(DrillSimError, ValueError):
    """A parameter is missing, unknown or outside its allowed range; the message names it."""


class NumericalFault(DrillSimError, FloatingPointError):
    """The integration produced a non-finite state; the simulator must be reset."""


class EnergyFault(NumericalFault):
    """The string created energy, or its energy balance drifted (the physics guard,
    Simulator._check_energy, string.balance); the message names the element (the line, its
    junction and depth), the time and the energy in J. The simulator must be reset."""


class HistoryOverflow(DrillSimError):
    """The exact-delay reference ran out of history storage (raise its capacity)."""
