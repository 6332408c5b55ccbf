"""The launch loop's plant steps between two TCU cycles in one compiled call (``fmu_src/launch_plant.c``).

The Python loop of :func:`.simulate.simulate_launches` is the reference; with ``plant="native"`` the steps
from a TCU cycle to the next (ten 1 ms steps at the shipped 10 ms period) run in C: the actuator, the
clutch FMU (the instance fmpy loaded, called through its ``fmi2SetReal``/``fmi2DoStep``/``fmi2GetReal``),
the engine and its idle governor, the driveline with its energy books, the slip energy into the thermal
network's accumulator and the launch record's per-step metrics. The TCU, the sensors, the thermal network's
step and the series' rows stay in Python. The C code keeps the Python expressions' order of operations (no
fused multiply-adds, libm's ``pow``), so both paths give the same results to the last bit on this machine;
``tests/test_launch_plant_block.py`` checks series, metrics, energy and events against the reference.

The library is compiled once per source version with zig (``ziglang``; the FMU's compiler) or the system
C compiler, and cached under ``$XDG_CACHE_HOME/cushion_clutch`` (default ``~/.cache``; :mod:`..fmu.hostlib`).
"""
from __future__ import annotations

from pathlib import Path

import cffi

from ..data import fmu_sources
from ..errors import FmuCallError
from ..fmu.hostlib import host_library

SOURCE, HEADER = "launch_plant.c", "launch_plant.h"
#: the most points of an engine torque curve the C step takes (lp_consts.curve_w)
MAX_CURVE = 32
FMI_FUNCTIONS = {-1: "fmi2SetReal", -2: "fmi2DoStep", -3: "fmi2GetReal"}
#: the first fields of ``lp_step_out``: a step's figures in the series' rows
ROW_FIELDS = ("w_e", "w_d", "v", "accel", "x_act", "t_dem", "t_cap", "t_c", "theta_cm_step", "theta_cs", "x_kiss",
              "throttle", "locked", "t_shaft")


def library() -> Path:
    """The compiled plant step (built on first use, cached by the sources' hash; :func:`.hostlib.host_library`).

    Raises
    ------
    RuntimeError
        If no compiler is found or the build fails (with the compiler's message).
    """
    return host_library("launch_plant", (SOURCE,), (HEADER,))


_FFI = None
_LIB = None


def _lib():
    global _FFI, _LIB
    if _LIB is None:
        ffi = cffi.FFI()
        ffi.cdef((fmu_sources() / HEADER).read_text())
        _LIB, _FFI = ffi.dlopen(str(library())), ffi
    return _FFI, _LIB


class NativePlant:
    """The compiled plant steps of one run, on the Python objects' state (copied in and out per block).

    Parameters
    ----------
    clutch : ClutchFmu
        The clutch FMU (its instance and held inputs are used).
    engine : EngineGovernor
    dl : Driveline
    h, act, w_lift, prefill : float
        Step (s), the actuator's decay per step, the driver's lift-off speed (rad/s), the pre-fill time (s).
    tcu_every, net_every : int
        Steps per TCU period and per thermal-network step.
    alpha_jerk, creep_nm : float
        The launch record's jerk-filter coefficient and creep threshold (N.m).
    """

    def __init__(self, clutch, engine, dl, h: float, act: float, w_lift: float, prefill: float, tcu_every: int,
                 net_every: int, alpha_jerk: float, creep_nm: float):
        if len(engine.w) > MAX_CURVE:
            raise ValueError(f"engine torque curve: {len(engine.w)} points, the native plant takes {MAX_CURVE}")
        ffi, lib = _lib()
        self.ffi, self.run_block = ffi, lib.lp_run_block
        self.clutch, self.engine, self.dl = clutch, engine, dl
        c = self.c = ffi.new("lp_consts *")
        fl = clutch._lib
        c.comp = clutch._c
        c.set_real = ffi.cast("lp_set_real", fl.fmi2SetReal)
        c.do_step = ffi.cast("lp_do_step", fl.fmi2DoStep)
        c.get_real = ffi.cast("lp_get_real", fl.fmi2GetReal)
        for i in range(3):
            c.vr_in[i], c.vr_out[i] = clutch._vr_in[i], clutch._vr_out[i]
        c.n_curve = len(engine.w)
        for i, (w, t) in enumerate(zip(engine.w, engine.t)):
            c.curve_w[i], c.curve_t[i] = w, t
        c.drag, c.kp, c.ki = engine.drag, engine.kp, engine.ki
        c.w_idle, c.w_stall, c.w_max = engine.w_idle, engine.w_stall, engine.w_max
        for name in ("i_tot", "r", "eta", "f_grade", "f_roll", "j_v", "j_e", "j_disc", "k", "c", "kappa", "air",
                     "brake_torque"):
            setattr(c, name, getattr(dl, name))
        c.h, c.act, c.w_lift, c.prefill, c.alpha_jerk, c.creep_nm = h, act, w_lift, prefill, alpha_jerk, creep_nm
        c.tcu_every, c.net_every = tcu_every, net_every
        self.s = ffi.new("lp_state *")
        self.b = ffi.new("lp_block *")
        self.max_steps = tcu_every
        self.out = ffi.new("lp_step_out[]", tcu_every)
        self.status = ffi.new("int *")
        # the same memory as double[] (the structs are doubles only): filled and read with one call each
        self._s = ffi.cast("double *", self.s)
        self._b = ffi.cast("double *", self.b)
        self._o = ffi.cast("double *", self.out)
        self._ns = ffi.sizeof("lp_state") // 8
        self._nb = ffi.sizeof("lp_block") // 8
        self.width = ffi.sizeof("lp_step_out") // 8
        #: index of each ``lp_step_out`` field in a step's values
        self.ix = {name: i for i, (name, _) in enumerate(ffi.typeof("lp_step_out").fields)}
        if tuple(self.ix)[:len(ROW_FIELDS)] != ROW_FIELDS:
            raise RuntimeError(f"{HEADER}: lp_step_out must start with {', '.join(ROW_FIELDS)}")

    def block(self, k0: int, n_steps: int, next_switch: float, slot_start: float, slot_end: float, countdown: int,
              x_cmd: float, pedal_level: float, t_dem: float, t_rate: float, engaged: bool, braking: bool,
              launching: bool, x_act: float, theta_cm: float, lifted: bool, stalled: bool, net_n: int,
              net_e: float, rec) -> tuple:
        """Run the steps from ``k0`` to the next TCU cycle (see ``lp_run_block``); the driveline, the engine,
        the clutch's held inputs and ``rec``'s accumulators are updated.

        Returns ``(steps, x_act, lifted, stalled, net_n, net_e, t_e, t_cap, theta_cs, x_kiss, out)`` with
        ``out`` the steps' figures, ``lp_step_out`` after ``lp_step_out`` (:attr:`width` values each, in
        the struct's order) in one flat list.

        Raises
        ------
        FmuCallError
            Naming the FMI function that failed, as the Python path does.
        """
        dl, en, eng, held = self.dl, self.dl.en, self.engine, self.clutch.held
        self._b[0:self._nb] = (k0, n_steps, next_switch, slot_start, slot_end, countdown, x_cmd, pedal_level, t_dem,
                               t_rate, engaged, braking, launching)
        self._s[0:self._ns] = (
            dl.w_e, dl.w_d, dl.v, dl.phi, dl.locked, en.engine_work, en.potential, en.slip, en.damping,
            en.resistance, en.brake, 0.0, 0.0, 0.0, eng.integral, 0.0, 0.0, x_act, theta_cm, 0.0, 0.0, 0.0,
            held[0], held[1], held[2], lifted, stalled, net_n, net_e, rec.lock_time is not None, rec.stall, 0.0,
            rec.slip_J, rec.a_filt, rec.jerk, rec.sq_err, rec.max_err, rec.sum_creep, rec.n_err, rec.n_creep)
        n = self.run_block(self.c, self.s, self.b, self.out, self.max_steps, self.status)
        (dl.w_e, dl.w_d, dl.v, dl.phi, locked, en.engine_work, en.potential, en.slip, en.damping, en.resistance,
         en.brake, dl.t_c, dl.slip_J, dl.slip_W, eng.integral, eng.throttle, t_e, x_act, _, t_cap, theta_cs, x_kiss,
         held[0], held[1], held[2], lifted, stalled, net_n, net_e, has_lock, rec_stall, lock_time, rec.slip_J,
         rec.a_filt, rec.jerk, rec.sq_err, rec.max_err, rec.sum_creep, n_err, n_creep) = self.ffi.unpack(self._s,
                                                                                                     self._ns)
        if n < 0:
            raise FmuCallError(FMI_FUNCTIONS[n], self.status[0], f"t={k0 * self.c.h!r} (native launch plant)")
        dl.locked = locked != 0.0
        if has_lock and rec.lock_time is None:
            rec.lock_time = lock_time
        rec.stall = rec_stall != 0.0
        rec.n_err, rec.n_creep = int(n_err), int(n_creep)
        return (n, x_act, lifted != 0.0, stalled != 0.0, int(net_n), net_e, t_e, t_cap, theta_cs, x_kiss,
                self.ffi.unpack(self._o, n * self.width))
