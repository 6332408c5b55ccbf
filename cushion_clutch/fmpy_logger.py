"""fmpy's FMI 2 logger proxy, made safe for a process that runs several FMUs (the one place that touches it).

fmpy (0.3.x) formats an FMU's printf-style log messages in a native proxy that keeps ONE global pointer to
the Python logger of the last ``addLoggerProxy`` call. ``simulate_fmu(..., logger=f)`` (and any custom
``fmi2CallbackFunctions``) leave it pointing at a ctypes callback that is freed when the run returns; an FMU
instantiated later with fmpy's default callbacks then calls freed memory as soon as it logs, and the
interpreter dies with a segmentation fault (the clutch FMUs log Warnings and Discards whatever ``loggingOn``).
:func:`restore_fmpy_logger` points the proxy back at fmpy's own printer, kept alive for the whole process;
the project calls it before every instance it makes with fmpy's default callbacks
(:class:`~cushion_clutch.launch.plant.fmu_client.FmuClient`, :func:`~cushion_clutch.launch.fleet.engagements.simulate`,
the test suite). FMI 3 loggers are not variadic and need no proxy.
"""
from __future__ import annotations

__all__ = ["restore_fmpy_logger"]

_KEPT: list = []        # the callbacks structure and fmpy's printer, alive as long as the process


def restore_fmpy_logger() -> None:
    """Point fmpy's native logger proxy at fmpy's default printer (``printLogMessage``), which lives as long as
    the process; harmless to call any number of times."""
    from ctypes import byref

    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, printLogMessage
    from fmpy.logging import addLoggerProxy

    if not _KEPT:
        _KEPT.extend([fmi2CallbackFunctions(), fmi2CallbackLoggerTYPE(printLogMessage)])
    callbacks, printer = _KEPT
    callbacks.logger = printer          # addLoggerProxy swaps its proxy into the structure: give it the printer
    addLoggerProxy(byref(callbacks))
