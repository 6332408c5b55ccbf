"""The clutch FMU as seen by the launch master: one thin choke point for every FMI call.

fmpy loads the FMU and runs its life cycle (instantiate, initialise,
terminate). The hot path (``fmi2SetReal``, ``fmi2DoStep``, ``fmi2GetReal``
once per communication step) calls the FMU's functions directly through
cffi (ABI mode, on the library fmpy loaded) with preallocated value-reference
and value arrays, which avoids fmpy's per-call list conversion and logging
wrapper; cffi's calls cost about 60 % of ctypes' (measured). Every status other
than fmi2OK/fmi2Warning raises :class:`~cushion_clutch.errors.FmuCallError`
naming the FMI function. ``held`` (the inputs last set) is shared with the compiled plant steps
(:mod:`.plant_block`), which call the same functions of the same instance.
"""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import cffi

from ...errors import FmuCallError

#: inputs and outputs exchanged every step, in this order
INPUTS = ("x_to", "theta_cm", "omega_slip")
OUTPUTS = ("torque", "theta_cs", "x_kiss")
#: read with them every step, kept in :attr:`ClutchFmu.out` (index 3): the plant's torque with mu read at the
#: friction surface is n mu R_eq clamp_force (simulate.py)
EXTRA_OUTPUTS = ("clamp_force",)


class ClutchFmu:
    """The clutch FMU (FMI 2 co-simulation).

    Parameters
    ----------
    fmu : Path
        The ``.fmu`` file (native or pythonfmu backend).
    start : dict of str to float
        Start values of parameters, SI (e.g. ``theta_a`` in K).
    """

    def __init__(self, fmu: Path, start: dict[str, float]):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        from ...fmpy_logger import restore_fmpy_logger

        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        missing = [n for n in INPUTS + OUTPUTS + EXTRA_OUTPUTS if n not in vr]
        if missing:
            raise ValueError(f"{fmu}: the FMU has no variable(s) {', '.join(missing)}")
        self.unzip = extract(str(fmu))
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName="clutch")
        s = self.slave
        restore_fmpy_logger()               # fmpy's default callbacks: never a logger freed by an earlier run
        s.instantiate()
        try:
            s.setupExperiment(startTime=0.0)
            ints = {k: v for k, v in start.items() if isinstance(v, int) and not isinstance(v, bool)}
            reals = {k: v for k, v in start.items() if k not in ints}     # ints: the table set (spring)
            if ints:
                s.setInteger([vr[k] for k in ints], list(ints.values()))
            if reals:
                s.setReal([vr[k] for k in reals], list(reals.values()))
            s.enterInitializationMode()
            s.exitInitializationMode()
        except Exception as exc:            # fmpy raises FMICallException; keep one typed error
            s.freeInstance()
            raise FmuCallError("fmi2 initialisation", getattr(exc, "status", 3), str(exc)) from exc
        self._ffi = ffi = cffi.FFI()
        ffi.cdef("""
            int fmi2SetReal(void *c, const unsigned int vr[], size_t nvr, const double value[]);
            int fmi2GetReal(void *c, const unsigned int vr[], size_t nvr, double value[]);
            int fmi2DoStep(void *c, double t, double h, int noSetFMUStatePriorToCurrentPoint);
        """)
        self._lib = ffi.dlopen(s.dll._name)          # the library fmpy loaded: the same handle
        self._c = ffi.cast("void *", s.component)
        self._vr_in = ffi.new("unsigned int[3]", [vr[n] for n in INPUTS])
        self._vr_out = ffi.new("unsigned int[4]", [vr[n] for n in OUTPUTS + EXTRA_OUTPUTS])
        self._v_in, self._v_out = ffi.new("double[3]"), ffi.new("double[4]")
        #: the last step's outputs: :data:`OUTPUTS` then :data:`EXTRA_OUTPUTS` (``out[3]`` the clamp force, N)
        self.out = self._v_out
        self.step = self._make_step()

    def _make_step(self):
        """The hot-path step as a closure over the cffi functions and arrays (no attribute look-ups)."""
        lib = self._lib
        set_real, do_step, get_real, comp = lib.fmi2SetReal, lib.fmi2DoStep, lib.fmi2GetReal, self._c
        vr_in, vr_out, v, o = self._vr_in, self._vr_out, self._v_in, self._v_out

        held = self.held = [math.nan] * 3    # the inputs last set: an FMU keeps its inputs, unchanged ones need no call

        def step(t: float, h: float, x_to: float, theta_cm: float, omega_slip: float) -> tuple[float, float, float]:
            """Set the inputs (m, K, rad/s), advance ``h`` s from ``t``; return torque (N.m), theta_cs (K), x_kiss (m).

            ``fmi2SetReal`` is skipped when the inputs equal those last set (held inputs: the clutch
            locked or open between TCU cycles).

            Raises
            ------
            FmuCallError
                Naming the FMI function that did not return fmi2OK/fmi2Warning.
            """
            if omega_slip != held[2] or x_to != held[0] or theta_cm != held[1]:    # NaN: never equal, set
                v[0] = held[0] = x_to
                v[1] = held[1] = theta_cm
                v[2] = held[2] = omega_slip
                st = set_real(comp, vr_in, 3, v)
                if st > 1:
                    held[0] = math.nan
                    raise FmuCallError("fmi2SetReal", st,
                                       f"x_to={x_to!r}, theta_cm={theta_cm!r}, omega_slip={omega_slip!r}")
            st = do_step(comp, t, h, 1)
            if st > 1:
                raise FmuCallError("fmi2DoStep", st, f"t={t!r}, h={h!r}")
            st = get_real(comp, vr_out, 4, o)
            if st > 1:
                raise FmuCallError("fmi2GetReal", st)
            return o[0], o[1], o[2]

        return step

    def friction_table(self):
        """The FMU's own friction table (``friction.csv`` in its resources) as a
        :class:`~cushion_clutch.model.friction.FrictionTable`, or None (the FMU's mu is the constant parameter)."""
        from ...model.friction import FrictionTable
        from ...model.table_format import FRICTION
        found = sorted(Path(self.unzip, "resources").rglob(FRICTION))
        return FrictionTable.from_csv(found[0]) if found else None

    def close(self) -> None:
        """Terminate and free the instance, delete the extracted FMU."""
        try:
            self.slave.terminate()
            self.slave.freeInstance()
        finally:
            self._ffi.dlclose(self._lib)        # drop our handle too, so the library can be deleted (Windows)
            shutil.rmtree(self.unzip, ignore_errors=True)
