"""The launch loop's plant steps between two TCU cycles in one compiled call (``fmu_src/hosts/launch_plant.c``).

The Python loop of :func:`.simulate.simulate_launches` is the reference; with ``plant="native"`` the steps
from a TCU cycle to the next (ten 1 ms steps at the shipped 10 ms period) run in C: the actuator, the
clutch FMU (the instance fmpy loaded, called through its ``fmi2SetReal``/``fmi2DoStep``/``fmi2GetReal``),
the engine and its idle governor, the driveline with its energy books, the plant's thermal network (its step
every TCU period, :meth:`.ThermalNetwork.step` written out) and the launch record's per-step metrics; a quiet
TCU period (the car braked at rest, the clutch open and retracted) is one C call too. The TCU, the sensors
and the series' rows stay in Python. The plant's state lives in C over a run (``lp_state``): the loop reads
its head (speeds, bearing, temperatures, flags) after each call, and the Python objects (driveline, engine,
launch records, the clutch's held inputs, the network's node temperatures) are brought up to date at a launch
slot's end and at the run's end. The C code keeps the Python expressions' order of operations (no fused
multiply-adds, libm's ``exp`` and ``pow``), so both paths give the same results to the last bit on this
machine; ``tests/test_launch_plant_block.py`` checks series, metrics, energy and events against the reference.

The library is compiled once per source version with zig (``ziglang``; the FMU's compiler) or the system
C compiler, and cached under ``$XDG_CACHE_HOME/cushion_clutch`` (default ``~/.cache``; :mod:`..fmu.hostlib`).
"""
from __future__ import annotations

from ...errors import FmuCallError
from ...fmu.hostlib import HostLibrary

SOURCE, HEADER = "launch_plant.c", "launch_plant.h"
#: the most points of an engine torque curve the C step takes (lp_consts.curve_w)
MAX_CURVE = 32
FMI_FUNCTIONS = {-1: "fmi2SetReal", -2: "fmi2DoStep", -3: "fmi2GetReal"}
#: the first fields of ``lp_step_out``: a step's figures in the series' rows
ROW_FIELDS = ("w_e", "w_d", "v", "accel", "x_act", "t_dem", "t_cap", "t_c", "theta_cm_step", "theta_cs", "x_kiss",
              "throttle", "locked", "t_shaft", "theta_surface", "theta_last")
#: the first fields of ``lp_state``: what the loop reads after every call
HEAD = ("steps", "n_events", "w_e", "w_d", "v", "phi", "locked", "t_e", "x_act", "theta_cm", "t_cap", "theta_cs",
        "x_kiss", "stalled", "has_lock", "lock_time", "throttle", "theta_cm_step", "theta_surface", "theta_last")
#: the most nodes of a thermal network the C step takes (lp_state.theta)
MAX_NODES = 16
#: the most temperatures and slip speeds of a friction table the C step takes (lp_consts.f_theta, f_omega)
MAX_FRICTION = 16


#: the compiled plant step (built on first use, cached by the sources' hash)
LIBRARY = HostLibrary("launch_plant", (SOURCE, "thermal_step.c"), (HEADER, "thermal_step.h", "host_export.h"))


class NativePlant:
    """The compiled plant steps of one run; the plant's state is held in C between :meth:`start` and
    :meth:`finish`.

    Parameters
    ----------
    clutch : ClutchFmu
        The clutch FMU (its instance and held inputs are used).
    engine : EngineGovernor
    dl : Driveline
    net : ThermalNetwork
        The plant's thermal network (its constants are copied; its ``theta`` is read by :meth:`start` and
        written by :meth:`finish`).
    h, act, w_lift, prefill : float
        Step (s), the actuator's decay per step, the driver's lift-off speed (rad/s), the pre-fill time (s).
    tcu_every, net_every : int
        Steps per TCU period and per thermal-network step.
    alpha_jerk, creep_nm : float
        The launch record's jerk-filter coefficient and creep threshold (N.m).
    """

    def __init__(self, clutch, engine, dl, net, h: float, act: float, w_lift: float, prefill: float,
                 tcu_every: int, net_every: int, alpha_jerk: float, creep_nm: float, mu_surface=None,
                 n_surfaces: float = 0.0, r_eq: float = 0.0):
        if len(engine.w) > MAX_CURVE:
            raise ValueError(f"engine torque curve: {len(engine.w)} points, the native plant takes {MAX_CURVE}")
        if len(net.theta) > MAX_NODES:
            raise ValueError(f"thermal network: {len(net.theta)} nodes, the native plant takes {MAX_NODES}")
        ffi, lib = LIBRARY.load()
        self.ffi, self.run_block, self.run_quiet = ffi, lib.lp_run_block, lib.lp_run_quiet
        self.clutch, self.engine, self.dl, self.net = clutch, engine, dl, net
        c = self.c = ffi.new("lp_consts *")
        fl = clutch._lib
        c.comp = clutch._c
        c.set_real = ffi.cast("lp_set_real", fl.fmi2SetReal)
        c.do_step = ffi.cast("lp_do_step", fl.fmi2DoStep)
        c.get_real = ffi.cast("lp_get_real", fl.fmi2GetReal)
        for i in range(3):
            c.vr_in[i] = clutch._vr_in[i]
        for i in range(4):
            c.vr_out[i] = clutch._vr_out[i]
        self._friction(mu_surface, n_surfaces, r_eq)
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
        self._network(net, net_every * h)
        self.s = ffi.new("lp_state *")
        self.b = ffi.new("lp_block *")
        self.max_steps = tcu_every
        self.out = ffi.new("lp_step_out[]", tcu_every)
        self.accel = ffi.new("double[]", tcu_every)
        self.status = ffi.new("int *")
        # the same memory as double[] (the structs are doubles only): filled and read with one call each
        self._s = ffi.cast("double *", self.s)
        self._b = ffi.cast("double *", self.b)
        self._o = ffi.cast("double *", self.out)
        #: the last block's figures as one double array (``lp_step_out`` after ``lp_step_out``, :attr:`ix`)
        self.values = self._o
        self._unpack = getattr(ffi, "_backend", ffi).unpack        # cffi's own, without api.py's wrapper
        self._nb = ffi.sizeof("lp_block") // 8
        self.width = ffi.sizeof("lp_step_out") // 8
        #: index of each ``lp_step_out`` field in a step's values
        self.ix = {name: i for i, (name, _) in enumerate(ffi.typeof("lp_step_out").fields)}
        if tuple(self.ix)[:len(ROW_FIELDS)] != ROW_FIELDS:
            raise RuntimeError(f"{HEADER}: lp_step_out must start with {', '.join(ROW_FIELDS)}")
        if tuple(name for name, _ in ffi.typeof("lp_state").fields)[:len(HEAD)] != HEAD:
            raise RuntimeError(f"{HEADER}: lp_state must start with {', '.join(HEAD)}")
        self.n_head = len(HEAD)
        #: the start of each step's figures, for :meth:`row`
        self._rows = [self._o + j * self.width for j in range(tcu_every)]
        self.n_row = len(ROW_FIELDS)

    def _friction(self, mu, n_surfaces: float, r_eq: float) -> None:
        """mu at the friction surface (``mu``: a FrictionTable, or None: the FMU's torque), as simulate.py."""
        c = self.c
        c.mu_surface = mu is not None
        if mu is None:
            return
        nt, nw = len(mu.theta_degC), len(mu.omega_rad_s)
        if nt > MAX_FRICTION or nw > MAX_FRICTION:
            raise ValueError(f"friction table: {nt} x {nw} points, the native plant takes {MAX_FRICTION} x "
                             f"{MAX_FRICTION}")
        c.f_nt, c.f_nw, c.n_surfaces, c.r_eq = nt, nw, n_surfaces, r_eq
        c.f_theta[0:nt] = mu.theta_degC
        c.f_omega[0:nw] = mu.omega_rad_s
        c.f_mu[0:nt * nw] = [v for row in mu.mu for v in row]

    def _network(self, net, dt: float) -> None:
        """The network's constants for both clamp states, the fixed nodes' decay factors at the step ``dt``
        (s), as :meth:`.ThermalNetwork.step` prepares them."""
        from ...model.thermal_network import FACINGS, SURFACES
        c = self.c
        c.net_n_nodes = len(net.theta)
        c.net_cm[0], c.net_cm[1] = FACINGS
        c.net_surface[0], c.net_surface[1] = SURFACES
        for clamped in (False, True):
            nodes, c.net_h0, c.net_hr, c.net_wr = net._prepare(clamped, dt)
            c.net_dt[clamped] = dt
            for (i, cap, gl, gr, area, on_disc, ge_te, gfix, share, decay), q in zip(nodes, c.net[clamped]):
                q.cap, q.gl, q.gr, q.area, q.on_disc, q.ge_te, q.gfix, q.share = (cap, gl, gr, area, on_disc, ge_te,
                                                                               gfix, share)
                q.fixed, q.decay = (0.0, 0.0) if decay is None else (1.0, decay)
        c.net_ta = net.theta_a

    def start(self, rec, x_act: float, theta_cm: float, t_e: float, t_cap: float, theta_cs: float,
              x_kiss: float) -> None:
        """Load the plant's state from the Python objects, the loop's values given and the launch record
        ``rec``; the network's slip-energy accumulator starts empty, the engine neither stalled nor lifted."""
        dl, en, eng, s = self.dl, self.dl.en, self.engine, self.s
        s.w_e, s.w_d, s.v, s.phi, s.locked = dl.w_e, dl.w_d, dl.v, dl.phi, dl.locked
        s.engine_work, s.potential, s.slip, s.damping = en.engine_work, en.potential, en.slip, en.damping
        s.resistance, s.brake = en.resistance, en.brake
        s.t_c, s.slip_J, s.slip_W = dl.t_c, dl.slip_J, dl.slip_W
        s.integral, s.throttle = eng.integral, eng.throttle
        s.held0, s.held1, s.held2 = self.clutch.held
        s.x_act, s.theta_cm, s.t_e, s.t_cap, s.theta_cs, s.x_kiss = x_act, theta_cm, t_e, t_cap, theta_cs, x_kiss
        s.net_n, s.net_e, s.lifted, s.stalled, s.n_events = 0.0, 0.0, 0.0, 0.0, 0.0
        s.theta[0:len(self.net.theta)] = self.net.theta
        s.theta_fs = self.net.theta_friction
        self._load(rec)

    def _load(self, rec) -> None:
        s = self.s
        s.has_lock = rec.lock_time is not None
        s.lock_time = rec.lock_time if rec.lock_time is not None else 0.0
        s.rec_stall, s.rec_slip_J, s.a_filt, s.jerk = rec.stall, rec.slip_J, rec.a_filt, rec.jerk
        s.sq_err, s.max_err, s.sum_creep, s.n_err, s.n_creep = (rec.sq_err, rec.max_err, rec.sum_creep, rec.n_err,
                                                               rec.n_creep)

    def _store(self, rec) -> None:
        s = self.s
        if s.has_lock and rec.lock_time is None:
            rec.lock_time = s.lock_time
        rec.stall, rec.slip_J, rec.a_filt, rec.jerk = s.rec_stall != 0.0, s.rec_slip_J, s.a_filt, s.jerk
        rec.sq_err, rec.max_err, rec.sum_creep = s.sq_err, s.max_err, s.sum_creep
        rec.n_err, rec.n_creep = int(s.n_err), int(s.n_creep)

    def new_slot(self, done, rec) -> None:
        """A launch slot ends: its record ``done`` takes the accumulators, ``rec`` (the next) gives them; the
        engine is no longer stalled nor lifted."""
        self._store(done)
        self._load(rec)
        self.s.stalled = self.s.lifted = 0.0

    def finish(self, rec) -> None:
        """The run's end: the Python objects (driveline and its energy books, engine, ``rec``, the clutch's
        held inputs, the network's node temperatures) take the plant's state."""
        dl, en, eng, s = self.dl, self.dl.en, self.engine, self.s
        self._store(rec)
        dl.w_e, dl.w_d, dl.v, dl.phi, dl.locked = s.w_e, s.w_d, s.v, s.phi, s.locked != 0.0
        en.engine_work, en.potential, en.slip, en.damping = s.engine_work, s.potential, s.slip, s.damping
        en.resistance, en.brake = s.resistance, s.brake
        dl.t_c, dl.slip_J, dl.slip_W = s.t_c, s.slip_J, s.slip_W
        eng.integral, eng.throttle = s.integral, s.throttle
        self.clutch.held[:] = (s.held0, s.held1, s.held2)
        self.net.theta[:] = self.ffi.unpack(s.theta, len(self.net.theta))

    def head(self) -> list:
        """The state's head (:data:`HEAD`), as after the last call."""
        return self._unpack(self._s, self.n_head)

    def row(self, j: int) -> list:
        """Step ``j``'s figures of the last block in the series' rows (:data:`ROW_FIELDS`)."""
        return self._unpack(self._rows[j], self.n_row)

    def accels(self, m: int) -> list:
        """The accelerations of the last block's ``m`` steps, m/s2."""
        return self._unpack(self.accel, m)

    def block(self, k0: int, n_steps: int, next_switch: float, slot_start: float, slot_end: float, countdown: int,
              x_cmd: float, pedal_level: float, t_dem: float, t_rate: float, engaged: bool, braking: bool,
              launching: bool) -> list:
        """Run the steps from ``k0`` to the next TCU cycle (see ``lp_run_block``); returns the state's head
        (:data:`HEAD`: ``steps`` their number; :meth:`row`, :meth:`accels` and :attr:`values` their
        figures).

        Raises
        ------
        FmuCallError
            Naming the FMI function that failed, as the Python path does.
        """
        self._b[0:self._nb] = (k0, n_steps, next_switch, slot_start, slot_end, countdown, x_cmd, pedal_level, t_dem,
                               t_rate, engaged, braking, launching)
        n = self.run_block(self.c, self.s, self.b, self.out, self.accel, self.max_steps, self.status)
        if n < 0:
            raise FmuCallError(FMI_FUNCTIONS[n], self.status[0], f"t={k0 * self.c.h!r} (native launch plant)")
        return self._unpack(self._s, self.n_head)

    def quiet(self, t: float, h_quiet: float, act_quiet: float) -> list | None:
        """One quiet TCU period from ``t`` (see ``lp_run_quiet``); the state's head (:data:`HEAD`, with the
        period's figures), or None if the clutch FMU returned a torque with the bearing retracted (the caller
        raises; :meth:`head` gives it).

        Raises
        ------
        FmuCallError
            Naming the FMI function that failed.
        """
        n = self.run_quiet(self.c, self.s, t, h_quiet, act_quiet, self.status)
        if n == -4:
            return None
        if n < 0:
            raise FmuCallError(FMI_FUNCTIONS[n], self.status[0], f"t={t!r}, h={h_quiet!r} (native launch plant)")
        return self._unpack(self._s, self.n_head)
