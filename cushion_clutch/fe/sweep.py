"""Temperature sweep: one ccx case per temperature, in parallel, cached, resumable.

The cases go through the FE case engine (:mod:`.cases`): a finished case leaves a
``result.json`` keyed by a hash of everything that decides its result, so a
rerun after a failure only computes what is missing. On one machine cases
run in threads (each thread waits on one ccx process); with a Dask
scheduler address they run on the cluster's workers instead.
"""
from __future__ import annotations

import datetime as _dt
import logging
import platform
from pathlib import Path
from typing import Callable

from .. import __version__
from ..errors import SweepError
from .cases import DEFAULT_CACHE, Case, CaseOutcome, run_cases
from .params import SpringParams
from .tables import Curve, curve_from_case, kiss_shift, progressivity, write_tables

log = logging.getLogger(__name__)

#: progress callback: (theta_degC, event, value); events "start", "increment", "done", "failed"
Progress = Callable[[float, str, float], None]
#: the engine's events as the sweep reports them ("cached" cases count as done)
_EVENTS = {"cached": "done", "start": "start", "increment": "increment", "done": "done", "failed": "failed"}


def run_sweep(params: SpringParams, *, cache_dir: Path = DEFAULT_CACHE, jobs: int | None = None,
              scheduler: str | object | None = None, paddles: int = 1,
              progress: Progress | None = None) -> dict[float, CaseOutcome]:
    """Solve every temperature of ``params.sweep``, reusing cached cases.

    Parameters
    ----------
    jobs : int, optional
        Parallel ccx jobs on this machine (default: number of cores). With
        fewer cases than jobs, each ccx gets the idle cores as threads.
    scheduler : str or distributed.Client, optional
        A Dask scheduler address (``tcp://host:8786``) or client; cases then
        run on its workers, which are checked first (:mod:`.cluster`; a scanned
        surface is shipped to them); the client needs no ccx.

    Raises
    ------
    SweepError
        If any case failed; the finished ones stay in the cache.
    ClusterError
        If the cluster cannot run the cases (named workers) or lost all its workers.
    """
    thetas = list(params.sweep.temperatures_degC)
    cases = [Case(params, t, paddles, f"theta = {t:g} degC") for t in thetas]

    def on_event(i: int, event: str, value: float) -> None:
        if progress:
            progress(thetas[i], _EVENTS[event], value)

    outcomes, failures = run_cases(cases, cache_dir=Path(cache_dir), jobs=jobs, scheduler=scheduler,
                                   on_event=on_event)
    if failures:
        raise SweepError({thetas[i]: exc for i, exc in failures.items()})
    return {t: o for t, o in sorted(zip(thetas, outcomes), key=lambda to: to[0]) if o is not None}


def build_tables(params: SpringParams, outcomes: dict[float, CaseOutcome], out_dir: Path,
                 *, wall_time_s: float | None = None) -> tuple[list[Curve], dict[float, float]]:
    """Turn solved cases into a table set in ``out_dir`` (atomic), with metadata."""
    curves = [curve_from_case(o.result, params.n_pairs, params.sweep.kiss_force_N)
              for o in outcomes.values()]
    shifts = kiss_shift(curves, params.material.reference_temperature_degC)
    crest = crest_growth(outcomes, params.material.reference_temperature_degC)
    prog = {f"{c.theta_degC:g}": progressivity(c.u_m, c.force_N) for c in curves}
    any_case = next(iter(outcomes.values()))
    metadata = {
        "generator": f"cushion_clutch {__version__} (cushion-clutch sweep)",
        "solver": {"name": "CalculiX ccx",
                   "version": ", ".join(sorted({o.ccx_version for o in outcomes.values()}))},
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "host": platform.node(),
        "spring": params.to_dict(),
        "far_end": far_end_metadata(params),
        "model": "half pair: paddle A against the carrier plane, composed in series "
                 "(pair travel = 2 x paddle travel)" if any_case.result.paddles == 1 else "full pair",
        "mesh": {"element_size_m": params.mesh.element_size_m, "element_type": params.mesh.element_type,
                 "nodes": any_case.n_nodes, "elements": any_case.n_elements},
        "units": {"theta_degC": "degC", "u_m": "m", "force_N": "N", "delta_kiss_m": "m"},
        "definitions": {
            "u_m": "compression of one paddle pair from its own kiss point at that temperature",
            "force_N": f"axial force of the whole spring ({params.n_pairs} pairs)",
            "kiss_point": f"where the force of one pair passes {params.sweep.kiss_force_N:g} N",
            "delta_kiss_m": "growth of the free height (kiss-point shift towards the open side) "
                            "relative to the reference temperature",
            "crest_growth_m": "rise of the pair's wave crests (mean radius) from heating alone, "
                              "relative to the reference temperature (crest_growth.csv)",
            "progressivity": "whole-spring tangent stiffness k (N/m, secant over 5 % of the travel) "
                             "at 20, 50 and 90 % of the travel from the kiss point to full "
                             "compression, and k(90 %)/k(20 %)",
        },
        "progressivity": prog,
        "kiss_point": {f"{t:g}": {"delta_kiss_m": shifts[t], "crest_growth_m": crest[t]}
                       for t in sorted(shifts)},
        "cases": {f"{t:g}": {"increments": o.stats.increments, "iterations": o.stats.iterations,
                             "cutbacks": o.stats.cutbacks, "wall_time_s": round(o.stats.wall_time_s, 2),
                             "crest_rise_m": o.result.crest_rise_m,
                             "full_compression_force_N": float(c.force_N[-1]),
                             "removed_decrease_N": c.removed_decrease_N}
                  for (t, o), c in zip(outcomes.items(), curves)},
        "run_wall_time_s": wall_time_s,
        "cases_from_cache": [t for t, o in outcomes.items() if o.from_cache],
        "note": "wall_time_s per case is ccx's own run time, also for cases served from the cache",
    }
    write_tables(out_dir, curves, params.material.reference_temperature_degC, metadata, crest)
    return curves, shifts


def far_end_metadata(params: SpringParams) -> dict:
    """How the far edge was held: its stiffness, N/m, and where it came from (the joint model or an override)."""
    from .joint import joint_stiffness
    if params.geometry.far_end != "elastic":
        return {"far_end": params.geometry.far_end}
    if params.carrier.far_end_stiffness_N_per_m is not None:
        return {"far_end_stiffness_N_per_m": float(params.carrier.far_end_stiffness_N_per_m),
                "source": "carrier.far_end_stiffness_N_per_m (override)"}
    j = joint_stiffness(params)
    return {"far_end_stiffness_N_per_m": j.series_N_per_m, "tab_N_per_m": j.tab_N_per_m,
            "rivets_N_per_m": j.rivets_N_per_m,
            "source": "predicted by cushion_clutch.fe.joint from [joint]: CalculiX tab model (C3D8I) in series "
                      "with the clamp rivets (Huth 1986)"}


def crest_growth(outcomes: dict[float, CaseOutcome], reference_degC: float) -> dict[float, float]:
    """Free-height growth of one pair at the crest from heating, relative to the reference, m.

    The half-pair model's crest rise stands for both paddles by symmetry;
    the full-pair model's paddle A is one of two equal paddles.
    """
    rise = {t: 2.0 * o.result.crest_rise_m for t, o in outcomes.items()}
    ref = min(rise, key=lambda t: abs(t - reference_degC))
    return {t: r - rise[ref] for t, r in rise.items()}
