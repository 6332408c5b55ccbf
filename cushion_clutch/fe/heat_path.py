"""The cushion spring's heat path identified from a transient thermal FE of the disc sector.

Pipeline (``cushion-clutch heat-path``): mesh the sector (:mod:`.heat_mesh`),
write the deck (:mod:`.heat_deck`), run ccx (:func:`.ccx.run_ccx`, the one
choke point), read every increment's temperatures, then

- theta_cm: the facing's mean temperature (heat-capacity weighted), theta_cs: the paddle's;
- U from the FE's own heat flow facing -> paddle (through the interface layer) against
  theta_cm - theta_cs (least squares, absolute W/K);
- tau and the gain U/(U+H) from an output-error least-squares fit of the paper's
  first-order ODE (eq. 2-4) to theta_cs given the FE's theta_cm; H = U (1 - gain)/gain,
  C = tau (U + H). C is then checked against the paddle steel's mass x c;
- a two-time-constant alternative (two parallel first-order lags) with its error.

The ODE is fitted in the form the FE integrates in time (backward Euler on the
same increments: the paddle's energy equation in the FE is exactly that), so the
time step does not bias tau. The energy balance sums heat in, stored and lost the
same way. Values are given for the whole disc (the model is 1/(2 n_pairs) of it).
"""
from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.optimize import least_squares

from .ccx import ccx_version, run_ccx
from .heat_fit import PAPER, first_order, two_lags
from .heat_deck import Schedule, launch_schedule, parse_temperatures, write_deck
from .heat_mesh import HeatMesh, sector_mesh
from .heat_params import STEEL_C_RANGE_J_PER_KG_K, UNCERTAIN, HeatPathParams
from .kiss_field import field_shape
from .params import SpringParams

#: in-plane element sizes, m (3x finer across the crest strip and the rivets): the default run and
#: ``--coarse``; convergence is judged on the last two, the uncertain inputs are re-solved on the first
MESHES_M = (6.0e-3, 4.0e-3, 3.0e-3)
COARSE_MESHES_M = (8.0e-3, 6.0e-3)
#: time increment during the slip, s (then 2x to 20 s after it, 4x to the next launch, 8x in the cool-down);
#: the ODE is fitted in the FE's own time discretisation, so tau does not depend on it to first order
DT_S = 0.5
COARSE_DT_S = 1.0
#: bars of the checks (issue 37): C within 10 % of the steel's mass x c (c in STEEL_C_RANGE), energy, mesh
BAR_C_FRACTION, BAR_ENERGY, BAR_TAU_MESH = 0.10, 0.01, 0.05


@dataclass(frozen=True)
class CaseResult:
    """One FE solve, reduced to the disc's lumped quantities.

    Attributes
    ----------
    element_size_m : float
    n_nodes, n_elements, increments : int
    wall_time_s : float
    t_s : ndarray
        End time of every increment, s (t = 0 excluded).
    dt_s : ndarray
        Increment lengths, s.
    theta_cm_degC, theta_cs_degC, theta_carrier_degC : ndarray
        Heat-capacity weighted means of facing, paddle, carrier, degC.
    q_facing_paddle_W, q_paddle_carrier_W : ndarray
        Heat flow facing -> paddle and paddle -> carrier (whole disc), W.
    heat_in_J, stored_J, lost_J : ndarray
        Cumulative heat in, heat stored (above the initial state), heat lost (whole disc), J.
    paddle_mass_kg : float
        Steel of the paddles (whole disc), kg.
    paddle_field : tuple
        Paddle element centres (r m, phi deg), their temperature rise over the paddle's mean rise, and the
        carrier's mean rise over the paddle's, averaged over the last launch period
        (:func:`.kiss_field.field_shape`).
    """

    element_size_m: float
    n_nodes: int
    n_elements: int
    increments: int
    wall_time_s: float
    t_s: np.ndarray
    dt_s: np.ndarray
    theta_cm_degC: np.ndarray
    theta_cs_degC: np.ndarray
    theta_carrier_degC: np.ndarray
    q_facing_paddle_W: np.ndarray
    q_paddle_carrier_W: np.ndarray
    heat_in_J: np.ndarray
    stored_J: np.ndarray
    lost_J: np.ndarray
    paddle_mass_kg: float
    paddle_field: tuple = ()


def films(hp: HeatPathParams) -> dict[str, float]:
    """Film coefficient of each face group, W/(m^2 K)."""
    return {"FRICTION": hp.friction_surface_W_per_m2_K, "HUB": hp.hub_W_per_m2_K,
            "CONVECTION": hp.convection_W_per_m2_K}


def schedule_for(mesh: HeatMesh, hp: HeatPathParams, dt_s: float = DT_S) -> Schedule:
    """The launch history: each launch puts ``slip_energy_J * facing_heat_share`` into the disc's facings."""
    area = float(mesh.face_area_m2["FRICTION"].sum())
    energy = hp.slip_energy_J * hp.facing_heat_share / mesh.disc_factor
    return launch_schedule(hp.launches, hp.launch_period_s, hp.slip_time_s, 2.0 * energy / (area * hp.slip_time_s),
                           hp.cooldown_s, hp.ambient_degC, dt_s)


def _flow(mesh: HeatMesh, temps: np.ndarray, name: str) -> np.ndarray:
    """Heat flow upwards (bottom face -> top face) through the thin layer ``name``, W (this model)."""
    e = mesh.element_sets[name]
    con = mesh.elements[e]
    height = mesh.nodes[con[:, 4], 2] - mesh.nodes[con[:, 0], 2]
    g = mesh.conductivity_W_per_m_K[e] * mesh.volume_m3[e] / height ** 2          # k A / t
    return (temps[:, con[:, :4]].mean(axis=2) - temps[:, con[:, 4:]].mean(axis=2)) @ g


def reduce_case(mesh: HeatMesh, hp: HeatPathParams, sched: Schedule, times: np.ndarray, temps: np.ndarray,
                wall_time_s: float) -> CaseResult:
    """Lumped quantities of one solve (``temps``: every increment, (frames, nodes), degC)."""
    t_inc = sched.increment_times()
    if len(times) != len(t_inc) or not np.allclose(times, t_inc, rtol=1e-6, atol=1e-6):
        raise ValueError(f"ccx printed {len(times)} frames, expected one per increment ({len(t_inc)})")
    dt = np.diff(np.r_[0.0, t_inc])
    f = mesh.disc_factor
    rc = mesh.density_kg_m3 * mesh.specific_heat_J_per_kg_K * mesh.volume_m3
    te = temps[:, mesh.elements].mean(axis=2)

    def mean(name: str) -> np.ndarray:
        e = mesh.element_sets[name]
        return te[:, e] @ rc[e] / rc[e].sum()

    stored = (te - hp.ambient_degC) @ rc * f
    loss = np.zeros(len(t_inc))
    for name, h in films(hp).items():
        if not len(mesh.faces.get(name, ())):
            continue
        fn = mesh.face_nodes(mesh.faces[name])
        loss += (temps[:, fn].mean(axis=2) - hp.ambient_degC) @ (h * mesh.face_area_m2[name])
    q_in = sched.flux(t_inc) * float(mesh.face_area_m2["FRICTION"].sum())
    return CaseResult(mesh.element_size_m, len(mesh.nodes), len(mesh.elements), len(t_inc), wall_time_s, t_inc, dt,
                      mean("FACING"), mean("PADDLE"), mean("CARRIER"),
                      _flow(mesh, temps, "INTERFACE") * -f, _flow(mesh, temps, "JOINT") * -f,
                      np.cumsum(q_in * dt) * f, stored, np.cumsum(loss * dt) * f, mesh.mass_kg("PADDLE") * f,
                      field_shape(mesh, t_inc, temps, hp.ambient_degC,
                                  ((hp.launches - 1) * hp.launch_period_s, hp.launches * hp.launch_period_s)))


def solve_case(spring: SpringParams, hp: HeatPathParams, element_size_m: float, workdir: Path,
               dt_s: float = DT_S, on_line: Callable[[str], None] | None = None) -> CaseResult:
    """Mesh, write, run ccx and reduce one case (the ``.dat`` is deleted after reading)."""
    mesh = sector_mesh(spring, hp, element_size_m)
    sched = schedule_for(mesh, hp, dt_s)
    start = time.perf_counter()
    run_ccx(write_deck(mesh, sched, films(hp)), workdir, "heat", on_line=on_line)
    dat = workdir / "heat.dat"
    times, temps = parse_temperatures(dat.read_text(), len(mesh.nodes))
    for suffix in (".dat", ".frd", ".cvg", ".sta"):
        (workdir / f"heat{suffix}").unlink(missing_ok=True)
    return reduce_case(mesh, hp, sched, times, temps, time.perf_counter() - start)


def identify(case: CaseResult, hp: HeatPathParams) -> dict:
    """U (from the FE's heat flow), tau and gain (ODE fit), H, C, errors, a two-lag alternative."""
    th_a = hp.ambient_degC
    d = case.theta_cm_degC - case.theta_cs_degC
    u_flow = float(np.dot(case.q_facing_paddle_W, d) / np.dot(d, d))
    e_d, e_q = np.cumsum(d * case.dt_s), np.cumsum(case.q_facing_paddle_W * case.dt_s)
    u_int = float(np.dot(e_q, e_d) / np.dot(e_d, e_d))         # the same on the integrated flow and difference
    u_resid = case.q_facing_paddle_W - u_flow * d
    u_rel = float(np.sqrt(np.mean(u_resid ** 2)) / np.sqrt(np.mean(case.q_facing_paddle_W ** 2)))

    def resid1(p):
        return first_order(case.theta_cm_degC, case.dt_s, th_a, math.exp(p[0]), 1 / (1 + math.exp(-p[1]))) \
            - case.theta_cs_degC
    fit = least_squares(resid1, [math.log(10.0), 2.0], x_scale=[1.0, 1.0])
    tau, gain = math.exp(fit.x[0]), 1 / (1 + math.exp(-fit.x[1]))
    err = resid1(fit.x)
    h = u_flow * (1.0 - gain) / gain
    c = tau * (u_flow + h)

    def resid2(p):
        return two_lags(case.theta_cm_degC, case.dt_s, th_a, p[0], math.exp(p[1]), p[2], math.exp(p[3])) \
            - case.theta_cs_degC
    fit2 = least_squares(resid2, [0.8 * gain, math.log(tau), 0.2 * gain, math.log(20 * tau)])
    err2 = resid2(fit2.x)
    k1, t1, k2, t2 = fit2.x[0], math.exp(fit2.x[1]), fit2.x[2], math.exp(fit2.x[3])
    if t1 > t2:
        k1, t1, k2, t2 = k2, t2, k1, t1
    rise = float(np.max(case.theta_cs_degC) - th_a)
    steel_c = hp.steel_specific_heat_J_per_kg_K
    return {
        "U_W_per_K": u_flow, "H_W_per_K": h, "C_J_per_K": c, "tau_s": tau, "gain": gain,
        "U_flow_fit_rel_rms": u_rel, "U_integrated_W_per_K": u_int,
        "ode_rms_error_K": float(np.sqrt(np.mean(err ** 2))), "ode_max_error_K": float(np.max(np.abs(err))),
        "theta_cs_max_rise_K": rise,
        "C_direct_J_per_K": case.paddle_mass_kg * steel_c,
        "C_over_mass_c": c / (case.paddle_mass_kg * steel_c),
        "C_over_mass_c_range": [c / (case.paddle_mass_kg * STEEL_C_RANGE_J_PER_KG_K[1]),
                                c / (case.paddle_mass_kg * STEEL_C_RANGE_J_PER_KG_K[0])],
        "two_lags": {"gain_1": k1, "tau_1_s": t1, "gain_2": k2, "tau_2_s": t2,
                     "rms_error_K": float(np.sqrt(np.mean(err2 ** 2))), "max_error_K": float(np.max(np.abs(err2)))},
        "energy_balance_error": float(abs(case.heat_in_J[-1] - case.stored_J[-1] - case.lost_J[-1]) / case.heat_in_J[-1]),
        "energy_balance_max_error": float(np.max(np.abs(case.heat_in_J - case.stored_J - case.lost_J)) / case.heat_in_J[-1]),
    }


def _solve_all(spring: SpringParams, jobs_: list[tuple[str, HeatPathParams, float]], out: Path, dt_s: float,
               jobs: int, say: Callable[[str], None]) -> dict[str, tuple[CaseResult, dict]]:
    """Solve and identify named cases, ``jobs`` ccx runs at a time (one thread each)."""
    from concurrent.futures import ThreadPoolExecutor

    def one(item):
        name, hp_, e = item
        case = solve_case(spring, hp_, e, out / "work" / name, dt_s)
        ident = identify(case, hp_)
        say(f"{name}: {case.n_nodes} nodes, {case.increments} increments, {case.wall_time_s:.0f} s: "
            f"tau {ident['tau_s']:.3g} s, gain {ident['gain']:.3g}")
        return name, (case, ident)

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        return dict(pool.map(one, jobs_))


def run_heat_path(spring: SpringParams, hp: HeatPathParams, out: Path, coarse: bool = False,
                  uncertainty: bool = True, jobs: int = 2, progress: Callable[[str], None] | None = None,
                  spring_source: str = "", command: str = "", kiss_shift: bool = False) -> dict:
    """Solve the meshes, identify, propagate the uncertain inputs; write ``heat_path.json``, the plot, the
    series, the parameter set (``heat_path_set.toml``) and the docs table (``heat_path_numbers.md``).

    Returns the JSON's content.
    """
    say = progress or (lambda msg: None)
    commit = _commit()                                  # before the runs: the code that made the numbers
    out.mkdir(parents=True, exist_ok=True)
    meshes = COARSE_MESHES_M if coarse else MESHES_M
    dt_s = COARSE_DT_S if coarse else DT_S
    todo = [(f"mesh_{e * 1e3:g}mm", hp, e) for e in meshes]
    if uncertainty:
        for name, bounds in UNCERTAIN.items():
            for label, value in zip(("low", "high"), bounds):
                todo.append((f"unc_{name}_{label}", dataclasses.replace(hp, **{name: value}), meshes[0]))
    say(f"{len(todo)} ccx runs ({len(meshes)} meshes"
        + (f", {len(todo) - len(meshes)} at the uncertain inputs' bounds" if uncertainty else "") + f"), {jobs} at a time")
    done = _solve_all(spring, todo, out, dt_s, jobs, say)
    cases = [done[f"mesh_{e * 1e3:g}mm"][0] for e in meshes]
    ids = [done[f"mesh_{e * 1e3:g}mm"][1] for e in meshes]
    best, ident = cases[-1], ids[-1]
    tau_change = abs(ids[-1]["tau_s"] - ids[-2]["tau_s"]) / ids[-1]["tau_s"]

    # uncertain inputs: the coarsest mesh at each bound; its relative change applies to the finest
    base_id = ids[0]
    keys = ("U_W_per_K", "H_W_per_K", "C_J_per_K", "tau_s", "gain")
    spread: dict[str, dict] = {}
    unc: dict[str, dict] = {}
    if uncertainty:
        for name, bounds in UNCERTAIN.items():
            spread[name] = {"low_value": bounds[0], "high_value": bounds[1],
                            **{label: {k: done[f"unc_{name}_{label}"][1][k] for k in keys} for label in ("low", "high")}}
        for key in keys:
            lo = math.sqrt(sum(min(0.0, min(s["low"][key], s["high"][key]) / base_id[key] - 1.0) ** 2
                               for s in spread.values()))
            hi = math.sqrt(sum(max(0.0, max(s["low"][key], s["high"][key]) / base_id[key] - 1.0) ** 2
                               for s in spread.values()))
            unc[key] = {"minus_fraction": lo, "plus_fraction": hi,
                        "low": ident[key] * (1 - lo), "high": ident[key] * (1 + hi)}

    c_lo, c_hi = (best.paddle_mass_kg * c for c in STEEL_C_RANGE_J_PER_KG_K)
    checks = {
        "C_within_10_percent_of_mass_c": bool((1 - BAR_C_FRACTION) * c_lo <= ident["C_J_per_K"] <= (1 + BAR_C_FRACTION) * c_hi),
        "energy_balance_within_1_percent": bool(ident["energy_balance_error"] <= BAR_ENERGY),
        "tau_mesh_change_within_5_percent": bool(tau_change <= BAR_TAU_MESH),
        "tau_finite_positive": bool(math.isfinite(ident["tau_s"]) and ident["tau_s"] > 0),
    }
    warnings = [f"check failed: {k}" for k, ok in checks.items() if not ok]
    if coarse:
        warnings.append("--coarse: quick check meshes and time steps, not the numbers to ship")
    result = {
        "U_W_per_K": ident["U_W_per_K"], "H_W_per_K": ident["H_W_per_K"], "C_J_per_K": ident["C_J_per_K"],
        "tau_s": ident["tau_s"], "gain": ident["gain"],
        "steel_mass_kg": best.paddle_mass_kg,
        "steel_specific_heat_J_per_kg_K": hp.steel_specific_heat_J_per_kg_K,
        "steel_specific_heat_range_J_per_kg_K": list(STEEL_C_RANGE_J_PER_KG_K),
        "C_direct_J_per_K": ident["C_direct_J_per_K"],
        "C_over_mass_c": ident["C_over_mass_c"],
        "energy_balance_error": ident["energy_balance_error"],
        "energy_balance_max_error": ident["energy_balance_max_error"],
        "tau_mesh_change": tau_change,
        "ode_rms_error_K": ident["ode_rms_error_K"], "ode_max_error_K": ident["ode_max_error_K"],
        "theta_cs_max_rise_K": ident["theta_cs_max_rise_K"],
        "U_flow_fit_rel_rms": ident["U_flow_fit_rel_rms"],
        "U_integrated_W_per_K": ident["U_integrated_W_per_K"],
        "two_lags": ident["two_lags"],
        "uncertainty": unc,
        "uncertainty_runs": spread,
        "checks": checks,
        "warnings": warnings,
        "meshes": [{"element_size_m": c.element_size_m, "nodes": c.n_nodes, "elements": c.n_elements,
                    "increments": c.increments, "wall_time_s": c.wall_time_s,
                    **{k: i[k] for k in (*keys, "ode_rms_error_K", "energy_balance_error")}}
                   for c, i in zip(cases, ids)],
        "time_increment_slip_s": dt_s,
        "paper": {**PAPER, "tau_s": PAPER["C_J_per_K"] / (PAPER["U_W_per_K"] + PAPER["H_W_per_K"]),
                  "gain": PAPER["U_W_per_K"] / (PAPER["U_W_per_K"] + PAPER["H_W_per_K"])},
        "scope": (f"whole disc: {spring.n_pairs} paddle pairs; the FE models 1/{2 * spring.n_pairs} "
                  "(one paddle, one facing, half the carrier) by rotational and mirror symmetry"),
        "inputs": dataclasses.asdict(hp),
        "spring": spring_source or spring.name,
        "coarse": coarse,
        "command": command,
        "commit": commit,
        "ccx_version": ccx_version(),
    }
    if kiss_shift:
        from .kiss_field import kiss_shift_study
        say("kiss shift at 195 degC: the FE's paddle field against a uniform temperature (4 structural cases)")
        result["kiss_shift"] = kiss_shift_study(spring, best.paddle_field, out, jobs=jobs, say=say)
    (out / "heat_path.json").write_text(json.dumps(result, indent=2) + "\n")
    _write_series(best, ident, hp, out / "heat_path_series.csv")
    from .heat_plots import plot_heat_path
    plot_heat_path(best, ident, hp, out / "heat_path.png")
    from ..model.thermal_set import set_toml
    from .heat_report import numbers_markdown
    (out / "heat_path_set.toml").write_text(set_toml(result))
    (out / "heat_path_numbers.md").write_text(numbers_markdown(result))
    return result


def _commit() -> str:
    """The package's git commit, ``-dirty`` if the FE code (``cushion_clutch/fe``, which holds the spring
    files too) has uncommitted changes; ``unknown`` outside a git checkout."""
    import subprocess
    here = Path(__file__).resolve().parent
    try:
        rev = subprocess.run(["git", "-C", str(here), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                             text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no", "--", "."],
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (rev + ("-dirty" if dirty else "")) if rev else "unknown"


def _write_series(case: CaseResult, ident: dict, hp: HeatPathParams, path: Path) -> None:
    ode = first_order(case.theta_cm_degC, case.dt_s, hp.ambient_degC, ident["tau_s"], ident["gain"])
    cols = np.column_stack([case.t_s, case.theta_cm_degC, case.theta_cs_degC, ode, case.theta_carrier_degC,
                            case.q_facing_paddle_W, case.heat_in_J, case.stored_J, case.lost_J])
    np.savetxt(path, cols, delimiter=",", fmt="%.6g",
               header="t_s,theta_cm_degC,theta_cs_fe_degC,theta_cs_ode_degC,theta_carrier_degC,"
                      "q_facing_paddle_W,heat_in_J,stored_J,lost_J", comments="")
