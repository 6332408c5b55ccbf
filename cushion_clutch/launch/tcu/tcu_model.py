"""The production TCU's clutch model torque, evaluated by the native clutch model (``fmu_src/hosts/tcu_model.c``).

The EKF (:mod:`.ekf`) asks its characteristic ``T(x_to, theta_cs, theta_cm)`` about 13,000 times in a
four-minute run, each time at other temperatures (its estimate moves), so the Python model recomputes its
cover frame on nearly every call (about 19 us). ``tcu_model.c`` answers the same torque through the clutch
model's public C functions (``clutch_tables.c``, ``clutch_cover.c``: the code the FMU runs) in about a
microsecond with the cffi call. The C table is loaded from the TCU's :class:`~..model.SpringTable` written
out with every float's exact decimal (``repr``), so it is the same table; the C cover equals the Python one
within about 1e-11 relative (``tests/test_native_speed.py``), so the two paths differ by round-off only
(``tests/test_tcu_model.py`` compares them over a scan and a production launch run).

``native=False`` (or a library that cannot be built, with a logged warning) keeps the Python
:func:`~..model.outputs` path, the reference. Arguments outside the model's ranges, and a state where the
diaphragm cannot hold the cushion, are always answered (or refused, with its ``ValueError``) by the Python
model, so both paths raise the same errors.

The library is compiled once per source version and cached (:class:`..fmu.hostlib.HostLibrary`).
"""
from __future__ import annotations

import dataclasses
import logging
import shutil
import tempfile
from pathlib import Path

from ...fmu.hostlib import HostLibrary
from ...model import ClutchParameters, SpringTable, outputs, x_to_for_torque
from ...model.clutch_model import THETA_MAX_K, THETA_MIN_K, X_TO_MAX, X_TO_MIN
from ...model.table_format import COLUMNS, FORCE_DEFLECTION, KISS_POINT

log = logging.getLogger(__name__)

#: the default of :class:`TcuClutchModel`'s ``native``: True evaluates with the native clutch model, False
#: with the Python model (the reference; e.g. to compare the two paths over whole runs)
NATIVE = True

SOURCES = ("tcu_model.c", "clutch_tables.c", "clutch_cover.c", "resource_uri.c")
HEADERS = ("tcu_model.h", "clutch_tables.h", "clutch_cover.h", "resource_uri.h", "host_export.h")


#: the compiled TCU clutch model (built on first use, cached by the sources' hash)
LIBRARY = HostLibrary("tcu_model", SOURCES, HEADERS)


def write_table(table: SpringTable, folder: Path) -> None:
    """Write ``table``'s force and kiss-point curves to ``folder/tables`` in the table format, every float
    as its exact decimal (``repr``), so a reader gets the same bits (no friction table: the TCU's mu is
    constant)."""
    out = folder / "tables"
    out.mkdir(parents=True, exist_ok=True)
    rows = [",".join(COLUMNS[FORCE_DEFLECTION])]
    for t, c in zip(table.theta_degC, table.curves):
        rows += [f"{t!r},{u!r},{f!r}" for u, f in zip(c.x, c.y)]
    (out / FORCE_DEFLECTION).write_text("\n".join(rows) + "\n")
    rows = [",".join(COLUMNS[KISS_POINT])] + [f"{t!r},{d!r}" for t, d in zip(table.theta_degC, table.delta_kiss_m)]
    (out / KISS_POINT).write_text("\n".join(rows) + "\n")


class TcuClutchModel:
    """The torque of the TCU's characteristic: ``outputs(x_to, theta_cs, table, p, theta_cm).torque``.

    Parameters
    ----------
    table : SpringTable
        The TCU's table. The native model takes the constant ``p.mu`` (the production TCU's nominal
        friction): a table with a friction table is evaluated by the Python model.
    p : ClutchParameters
    native : bool, optional
        Evaluate with the native clutch model (default :data:`NATIVE`); False, or if it cannot be built or
        loaded (a warning is logged), with the Python model.
    """

    def __init__(self, table: SpringTable, p: ClutchParameters, native: bool | None = None):
        native = NATIVE if native is None else native
        self.table, self.p = table, p
        # the Python model checks the table and the parameters once (the same error as on a first call)
        outputs(min(max(p.x_kiss_ref, X_TO_MIN), X_TO_MAX), table.theta_min_K, table, p, table.theta_min_K)
        self._m = None
        if native and table.friction is None:
            try:
                self._open()
            except (RuntimeError, OSError, ValueError) as exc:
                log.warning("the native TCU clutch model is not available, using the Python model: %s", exc)
                self._m = None

    def _open(self) -> None:
        ffi, lib = LIBRARY.load()
        p = self.p
        folder = Path(tempfile.mkdtemp(prefix="tcu_model_"))
        try:
            write_table(self.table, folder)
            cover = [float(getattr(p.cover, f.name)) for f in dataclasses.fields(p.cover)]
            err = ffi.new("char[]", 600)
            m = lib.tm_open(str(folder).encode(), ffi.new("double[]", cover), len(cover), p.lever_ratio,
                            p.x_kiss_ref, p.facing_wear, p.n_surfaces * p.mu * p.R_eq, err, 600)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        if m == ffi.NULL:
            raise RuntimeError(ffi.string(err).decode(errors="replace"))
        self._m = ffi.gc(m, lib.tm_close)
        self._torque = lib.tm_torque
        self._inverse = lib.tm_x_for_torque

    @property
    def native(self) -> bool:
        """True if the torque is evaluated by the native clutch model."""
        return self._m is not None

    def torque(self, x_to: float, theta_cs: float, theta_cm: float) -> float:
        """Torque (N.m) at bearing position ``x_to`` (m), ``theta_cs`` and ``theta_cm`` (K).

        Raises
        ------
        ValueError
            As :func:`~..model.outputs`, naming the argument outside its range.
        """
        if self._m is not None and X_TO_MIN <= x_to <= X_TO_MAX and THETA_MIN_K <= theta_cs <= THETA_MAX_K \
                and THETA_MIN_K <= theta_cm <= THETA_MAX_K:
            t = self._torque(self._m, x_to, theta_cs, theta_cm)
            if t == t:
                return t
        return outputs(x_to, theta_cs, self.table, self.p, theta_cm).torque

    def x_for_torque(self, torque: float, theta_cs: float, theta_cm: float, tol_m: float = 1e-12) -> float:
        """Smallest bearing position (m) whose torque reaches ``torque`` (N.m) at ``theta_cs`` and ``theta_cm``
        (K): ``x_to_for_torque(torque, theta_cs, table, p, tol_m, theta_cm)`` (at or below the cushion's first
        force its first-contact position, above the closed capacity the lift-off position).

        The native inverse finds the cushion's compression as the Python one does (the same bracket, to
        ``tol_m`` over the lever ratio) and its position through the forward map (the secant method), so the
        two agree within about ``tol_m`` (``tests/test_tcu_model.py``).

        Raises
        ------
        ValueError
            As :func:`~..model.x_to_for_torque`, naming the argument outside its range.
        """
        if self._m is not None and -1e9 <= torque <= 1e9 and THETA_MIN_K <= theta_cs <= THETA_MAX_K \
                and THETA_MIN_K <= theta_cm <= THETA_MAX_K and 0.0 < tol_m <= 1.0:
            x = self._inverse(self._m, torque, theta_cs, theta_cm, tol_m)
            if x == x:
                return x
        return x_to_for_torque(torque, theta_cs, self.table, self.p, tol_m, theta_cm=theta_cm)
