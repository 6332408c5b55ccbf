"""Tolerance study results: per-sample figures, P5/P50/P95 bands, plot and the P5/P95 table sets.

Every sample's table set is written with the sweep's own table writer
(``<study>/samples/s###``); the torque characteristic T(x_to, theta) of a
sample comes from the clutch model the FMU runs
(:func:`cushion_clutch.model.clutch_model.outputs`), with the model's
default clutch parameters and the kiss point at the bearing moved by the
sample's free-height deviation: ``x_kiss_ref = x_kiss_ref_nominal -
lever_ratio * (H_sample - H_nominal)``, H the pair's free height at the
reference temperature. Percentiles are ``numpy.percentile`` (linear) over
the drawn samples (the nominal spring is shown, not counted).
"""
from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...model import KELVIN, ClutchParameters, SpringTable, outputs
from ..geometry import half_pair_assembly
from ..cases import CaseOutcome
from ..sweep import build_tables
from ..tables import curve_from_case
from .tolerance import Sample

PERCENTILES = (5.0, 50.0, 95.0)
#: fewer drawn samples than this make P5 and P95 (nearly) the extremes of the draw
MIN_SAMPLES_FOR_PERCENTILES = 20


def percentile_warnings(samples: int) -> list[str]:
    """Why the P5/P95 of ``samples`` drawn springs should not be read as percentiles (empty if fine)."""
    if samples >= MIN_SAMPLES_FOR_PERCENTILES:
        return []
    return [f"only {samples} samples: P5 and P95 of fewer than {MIN_SAMPLES_FOR_PERCENTILES} draws are "
            f"close to the smallest and largest drawn values (linear interpolation between order "
            f"statistics), not estimates of the production P5/P95; use --samples "
            f"{MIN_SAMPLES_FOR_PERCENTILES} or more"]
RANK_BY = {"torque": "torque at the nominal half-engaged bearing position at the reference temperature",
           "force": "force at full compression at the reference temperature",
           "kiss": "kiss-point shift at the kiss temperature (a larger shift is ranked lower: less torque)"}


@dataclass(frozen=True)
class SampleSummary:
    """One sample's figures (SI) and its table set."""

    sample: Sample
    tables: Path
    table: SpringTable
    free_height_m: float
    x_kiss_ref_m: float
    delta_kiss_m: dict
    force_full_N: float
    u_full_m: float


def pair_free_height(params, outcome: CaseOutcome) -> float:
    """Plate-to-plate height of a paddle pair at its kiss point, m (2 z_plate - kiss travel)."""
    z_top = half_pair_assembly(params.geometry, params.mesh.element_size_m,
                               params.solver.initial_gap_m).plates[0].z_face_m
    curve = curve_from_case(outcome.result, params.n_pairs, params.sweep.kiss_force_N)
    return 2.0 * z_top - curve.kiss_travel_m


def summarize(samples: list[Sample], outcomes: list[dict[float, CaseOutcome]], study_dir: Path,
              clutch: ClutchParameters | None = None) -> list[SampleSummary]:
    """Write every sample's table set and gather its figures; ``samples[0]`` is the nominal."""
    clutch = clutch or ClutchParameters()
    out = []
    h_nominal = None
    for s, o in zip(samples, outcomes):
        p = s.params.replace(sweep={"temperatures_degC": tuple(o)})
        folder = Path(study_dir) / "samples" / f"s{s.index:03d}"
        curves, shifts = build_tables(p, o, folder)
        ref = p.material.reference_temperature_degC
        h = pair_free_height(p, o[ref])
        h_nominal = h if h_nominal is None else h_nominal
        c_ref = next(c for c in curves if c.theta_degC == ref)
        out.append(SampleSummary(s, folder, SpringTable.from_dir(folder), h,
                                 clutch.x_kiss_ref - clutch.lever_ratio * (h - h_nominal), shifts,
                                 float(c_ref.force_N[-1]), float(c_ref.u_m[-1])))
    return out


def torque_curve(s: SampleSummary, x_to: np.ndarray, theta_degC: float,
                 clutch: ClutchParameters | None = None) -> np.ndarray:
    """T(x_to) of a sample at ``theta_degC`` through the FMU's model, N.m."""
    clutch = clutch or ClutchParameters()
    p = ClutchParameters(**{**vars(clutch), "x_kiss_ref": s.x_kiss_ref_m})
    return np.array([outputs(float(x), theta_degC + KELVIN, s.table, p).torque for x in x_to])


@dataclass(frozen=True)
class Bands:
    """Percentile bands, arrays of shape (3, ...) for P5, P50, P95."""

    temperatures_degC: tuple
    u_m: np.ndarray
    force_N: dict
    delta_kiss_m: np.ndarray
    x_to_m: np.ndarray
    torque_Nm: dict
    x_half_m: float
    rows: list
    kiss_theta_degC: float
    ref_degC: float


def compute_bands(summ: list[SampleSummary], temperatures: tuple, clutch: ClutchParameters | None = None,
                  n_points: int = 200) -> Bands:
    """Bands of F(u, theta), delta_kiss(theta) and T(x_to, theta), and the per-sample rows."""
    clutch = clutch or ClutchParameters()
    nominal, drawn = summ[0], summ[1:]
    ref = nominal.sample.params.material.reference_temperature_degC
    kiss_t = 195.0 if 195.0 in temperatures else max(temperatures)
    u_hi = min(float(s.table.full_compression(t)) for s in summ for t in temperatures)
    u = np.linspace(0.0, u_hi, n_points)
    force = {t: np.percentile([[s.table.force(float(x), t) for x in u] for s in drawn], PERCENTILES, axis=0)
             for t in temperatures}
    kiss = np.percentile([[s.delta_kiss_m[t] for t in temperatures] for s in drawn], PERCENTILES, axis=0)
    x_half = clutch.x_kiss_ref + clutch.lever_ratio * 0.5 * nominal.u_full_m
    lo = min(s.x_kiss_ref_m - clutch.lever_ratio * (s.delta_kiss_m[t] - s.table.first_contact(t))
             for s in summ for t in temperatures)
    x_to = np.linspace(lo, clutch.x_kiss_ref + clutch.lever_ratio * nominal.u_full_m, n_points)
    torque = {t: np.percentile([torque_curve(s, x_to, t, clutch) for s in drawn], PERCENTILES, axis=0)
              for t in temperatures}
    rows = []
    for s in summ:
        row = {"sample": s.sample.index, **{f"{k}_deviation": v for k, v in s.sample.deviations.items()},
               "thickness_m": s.sample.params.geometry.thickness_m,
               "wave_height_m": s.sample.params.geometry.wave_height_m,
               "youngs_modulus_20degC_Pa": s.sample.params.material.youngs_modulus(20.0),
               "free_height_offset_m": s.free_height_m - nominal.free_height_m,
               f"delta_kiss_{kiss_t:g}degC_m": s.delta_kiss_m[kiss_t],
               f"force_full_{ref:g}degC_N": s.force_full_N, f"u_full_{ref:g}degC_m": s.u_full_m}
        for t in temperatures:
            row[f"torque_half_{t:g}degC_Nm"] = float(torque_curve(s, np.array([x_half]), t, clutch)[0])
        rows.append(row)
    return Bands(tuple(temperatures), u, force, kiss, x_to, torque, x_half, rows, kiss_t, ref)


def rank_value(row: dict, rank_by: str, bands: Bands) -> float:
    """The figure a sample is ranked by (higher = more torque)."""
    if rank_by == "torque":
        return row[f"torque_half_{bands.ref_degC:g}degC_Nm"]
    if rank_by == "force":
        return row[f"force_full_{bands.ref_degC:g}degC_N"]
    return -row[f"delta_kiss_{bands.kiss_theta_degC:g}degC_m"]


def pick_percentile_samples(bands: Bands, rank_by: str) -> dict[float, tuple[int, float, float]]:
    """For P5 and P95: (sample index, its value, the percentile value) of the closest drawn sample."""
    rows = bands.rows[1:]
    values = np.array([rank_value(r, rank_by, bands) for r in rows])
    out = {}
    for q in (5.0, 95.0):
        target = float(np.percentile(values, q))
        k = int(np.argmin(np.abs(values - target)))
        out[q] = (rows[k]["sample"], float(values[k]), target)
    return out


def write_outputs(bands: Bands, summ: list[SampleSummary], study_dir: Path) -> list[Path]:
    """samples.csv, force_bands.csv, kiss_bands.csv, torque_bands.csv in ``study_dir``."""
    study_dir = Path(study_dir)
    paths = []
    path = study_dir / "samples.csv"
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(bands.rows[0]))
        w.writeheader()
        for r in bands.rows:
            w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in r.items()})
    paths.append(path)
    nominal = summ[0]
    specs = [("force_bands.csv", ["theta_degC", "u_m", "force_p05_N", "force_p50_N", "force_p95_N",
                                  "force_nominal_N"],
              lambda t: zip(bands.u_m, *bands.force_N[t], [nominal.table.force(float(x), t) for x in bands.u_m])),
             ("torque_bands.csv", ["theta_degC", "x_to_m", "torque_p05_Nm", "torque_p50_Nm", "torque_p95_Nm",
                                   "torque_nominal_Nm"],
              lambda t: zip(bands.x_to_m, *bands.torque_Nm[t], torque_curve(nominal, bands.x_to_m, t)))]
    for name, header, rows in specs:
        path = study_dir / name
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            for t in bands.temperatures_degC:
                for row in rows(t):
                    w.writerow([f"{t:g}", *(f"{v:.9g}" for v in row)])
        paths.append(path)
    path = study_dir / "kiss_bands.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["theta_degC", "delta_kiss_p05_m", "delta_kiss_p50_m", "delta_kiss_p95_m",
                    "delta_kiss_nominal_m"])
        for j, t in enumerate(bands.temperatures_degC):
            w.writerow([f"{t:g}", *(f"{v:.9g}" for v in bands.delta_kiss_m[:, j]), f"{nominal.delta_kiss_m[t]:.9g}"])
    paths.append(path)
    return paths


def write_percentile_set(summ: list[SampleSummary], outcomes: list[dict[float, CaseOutcome]], pick: tuple,
                         q: float, rank_by: str, out_dir: Path, warnings: list[str] = ()) -> Path:
    """The table set of the sample closest to percentile ``q``, with that choice in metadata.json."""
    index, value, target = pick
    k = next(i for i, s in enumerate(summ) if s.sample.index == index)
    s = summ[k]
    p = s.sample.params.replace(sweep={"temperatures_degC": tuple(outcomes[k])})
    build_tables(p, outcomes[k], out_dir)
    meta_path = Path(out_dir) / "metadata.json"
    meta = json.loads(meta_path.read_text())
    meta["tolerance_study"] = {
        "percentile": q, "sample": index, "rank_by": RANK_BY[rank_by], "sample_value": value,
        "percentile_value": target, "deviations": s.sample.deviations,
        "free_height_offset_m": s.free_height_m - summ[0].free_height_m,
        "x_kiss_ref_m": s.x_kiss_ref_m, "warnings": list(warnings),
        "note": "u and delta_kiss are relative to this sample's own kiss point; build-fmu takes "
                "x_kiss_ref_m as the start value of the FMU parameter x_kiss_ref, which places it "
                "against the nominal spring's kiss point"}
    tmp = meta_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(meta, indent=2) + "\n")
    os.replace(tmp, meta_path)
    return Path(out_dir)


def write_nominal_set(summ: list[SampleSummary], outcomes: list[dict[float, CaseOutcome]], out_dir: Path) -> Path:
    """The nominal spring's table set (sample 0) in ``out_dir``, its kiss point in metadata.json (for the band's FMU)."""
    s = summ[0]
    p = s.sample.params.replace(sweep={"temperatures_degC": tuple(outcomes[0])})
    build_tables(p, outcomes[0], out_dir)
    meta_path = Path(out_dir) / "metadata.json"
    meta = json.loads(meta_path.read_text())
    meta["tolerance_study"] = {"sample": s.sample.index, "nominal": True, "x_kiss_ref_m": s.x_kiss_ref_m,
                               "note": "the study's nominal spring, on the study's mesh"}
    tmp = meta_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(meta, indent=2) + "\n")
    os.replace(tmp, meta_path)
    return Path(out_dir)


@dataclass(frozen=True)
class StudyResult:
    """What :func:`tolerance_study` wrote and found."""

    study_dir: Path
    bands: Bands
    summaries: list
    picks: dict
    sets: dict
    files: list
    warnings: list
    cases: int
    cases_from_cache: int
    wall_time_s: float
    band_fmu: Path | None = None


def tolerance_study(params, *, samples: int, temperatures: tuple, out: Path, method: str = "lhs",
                    seed: int = 0, rank_by: str = "torque", cache_dir: Path | None = None,
                    scheduler=None, workers: int | None = None, progress=None,
                    build_band=None) -> StudyResult:
    """Run a whole study: draw, solve (Dask, cached), summarize, bands, plot, P5/P95 table sets.

    Writes ``<out>/<name>_tolerance/`` (samples.csv, *_bands.csv, tolerance_bands.png,
    samples/s###/) and the table sets ``<out>/<name>_p05/`` and ``<out>/<name>_p95/``. With ``build_band``
    (a function of the table folders nominal, P5, P95 that builds one FMU carrying them and returns its path:
    the command line passes :func:`cushion_clutch.fmu.build.build_fmu`; the FE stage knows no FMU) also
    ``<out>/<name>_nominal/`` and that FMU, its sets chosen by its parameter ``spring``.
    """
    import time

    from ..cases import DEFAULT_CACHE
    from .tolerance import make_samples, run_study
    from .tolerance_plots import plot_bands

    temperatures = tuple(sorted(set(float(t) for t in temperatures)))
    params = params.replace(sweep={"temperatures_degC": temperatures})   # checks the reference is there
    drawn = make_samples(params, samples, method, seed)
    start = time.perf_counter()
    outcomes = run_study(drawn, temperatures, cache_dir=cache_dir or DEFAULT_CACHE, scheduler=scheduler,
                         workers=workers, progress=progress)
    wall = time.perf_counter() - start
    study_dir = Path(out) / f"{params.name}_tolerance"
    study_dir.mkdir(parents=True, exist_ok=True)
    summ = summarize(drawn, outcomes, study_dir)
    bands = compute_bands(summ, temperatures)
    files = write_outputs(bands, summ, study_dir)
    files.append(plot_bands(bands, summ, study_dir / "tolerance_bands.png",
                            f"Spring '{params.name}': {samples} samples ({method.upper()}, seed {seed})"))
    picks = pick_percentile_samples(bands, rank_by)
    warnings = percentile_warnings(samples)
    sets = {q: write_percentile_set(summ, outcomes, picks[q], q, rank_by,
                                    Path(out) / f"{params.name}_p{int(q):02d}", warnings) for q in picks}
    n_cached = sum(o.from_cache for r in outcomes for o in r.values())
    (study_dir / "study.json").write_text(json.dumps({
        "spring": params.name, "samples": samples, "method": method, "seed": seed,
        "temperatures_degC": list(temperatures), "mesh_element_size_m": params.mesh.element_size_m,
        "tolerances_sd": params.tolerances.declared(), "truncated_at_sd": 3.0, "rank_by": RANK_BY[rank_by],
        "percentile_sets": {f"p{int(q):02d}": {"sample": v[0], "value": v[1], "percentile_value": v[2],
                                               "folder": str(sets[q]),
                                               "x_kiss_ref_m": next(x.x_kiss_ref_m for x in summ
                                                                    if x.sample.index == v[0])}
                           for q, v in picks.items()},
        "cases": len(drawn) * len(temperatures), "cases_from_cache": n_cached, "wall_time_s": wall,
        "warnings": warnings}, indent=2) + "\n")
    fmu = None
    if build_band is not None:
        nominal = write_nominal_set(summ, outcomes, Path(out) / f"{params.name}_nominal")
        fmu = build_band([nominal, *(sets[q] for q in sorted(sets))])
    return StudyResult(study_dir, bands, summ, picks, sets, files, warnings, len(drawn) * len(temperatures),
                       n_cached, wall, fmu)
