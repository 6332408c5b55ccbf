"""The fleet study: a population's samples (:mod:`.population`), each a sequence of launches with each TCU, on Dask.

Every sample runs on a worker (:func:`run_sample`): its scenario is drawn from the population with the run's
seed, then simulated with each chosen TCU (:func:`.report.run_all`), and its row per TCU keeps, of every launch
metric, the worst value over the sample's launches (:data:`WORST`). The cluster is the FE sweeps' one choke
point (:func:`cushion_clutch.fe.cluster.open_cluster`, checked without CalculiX): a LocalCluster by default, or
a scheduler's address. A sample that fails is reported with the worker it ran on; lost workers are named.

Outputs in ``--out`` (``DIR``):

* ``fleet_parts/sample_NNNNNN.json``: each finished sample, written as it ends (a rerun with the same
  population, seed and TCUs keeps them and runs only the rest: resumable);
* ``fleet_samples.parquet``: one row per sample and TCU (``sample``, ``tcu``, the drawn values, every
  metric's worst over the sample's launches, ``launches``, ``lockups``);
* ``fleet_summary.csv``: per TCU and metric the P50, P95, P99 and maximum over the samples (NaN samples,
  e.g. no launch with a measured value, left out);
* ``fleet.png``: the CDF of the characteristic error per TCU, the error against the ambient temperature
  and against the facing wear;
* ``fleet_run.json``: what ran (population, seed, TCUs, samples) and how fast (launches per second per core).
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ...errors import ClusterError, ParameterError
from ..results.metrics import METRIC_COLUMNS, SUMMARY
from .population import Population, draw, sample_scenario

SAMPLES_FILE = "fleet_samples.parquet"
SUMMARY_FILE = "fleet_summary.csv"
PARTS = "fleet_parts"
RUN_FILE = "fleet_run.json"
PLOT_FILE = "fleet.png"
#: the summary's percentiles
PERCENTILES = (50, 95, 99)
#: the bar of issue 38 on production's P99 characteristic error (3 % of the 312 N.m closed torque), N.m
ERROR_BAR_NM = 9.4

_BOOLEAN = ("hot", "engine_stall", "launch_possible", "stranded")
_SKIP = ("tcu", "launch", "demand_level", "phase")
_ABSMAX = tuple(c for c, how in SUMMARY if how == "absmax")
#: how each launch metric's worst over a sample's launches is taken: "max", "absmax" (the signed value of
#: the largest magnitude) or "count" (booleans: the launches for which it is true)
WORST = {c: ("count" if c in _BOOLEAN else "absmax" if c in _ABSMAX else "max")
         for c in METRIC_COLUMNS if c not in _SKIP}
#: the drawn values of a sample, as columns
PARAMS = ("mass_kg", "trailer", "trailer_mass_kg", "grade_percent", "ambient_degC", "start_degC", "pedal",
          "interval_s", "kiss_offset_m", "facing_wear_m", "spring", "sensor_seed", "tcu_seed")
COLUMNS = ("sample", "tcu", *PARAMS, "launches", "lockups", *WORST)


def _worst(values: list, how: str):
    if how == "count":
        return int(sum(bool(v) for v in values))
    vals = [float(v) for v in values if v is not None and not math.isnan(float(v))]
    if not vals:
        return math.nan
    return max(vals, key=abs) if how == "absmax" else max(vals)


def sample_rows(pop: Population, seed: int, i: int, tcus: Sequence[str], fmus: dict, tables: dict) -> list[dict]:
    """Sample ``i``: its launches with each TCU; one row per TCU (:data:`COLUMNS`).

    ``fmus`` and ``tables``: the plant FMU (path) and the TCUs' table (SpringTable) per spring set name.
    """
    from ..report import run_all

    s = draw(pop, seed, i)
    sc = sample_scenario(pop, s)
    results = run_all(Path(fmus[s.spring]), sc, tables[s.spring], tuple(tcus))
    params = {k: v for k, v in asdict(s).items() if k != "sample"}
    rows = []
    for name, res in results.items():
        m = res.metrics
        row = {"sample": int(i), "tcu": name, **params, "launches": len(m),
               "lockups": sum(math.isfinite(x["engagement_time_s"]) for x in m)}
        row.update({c: _worst([x.get(c, math.nan) for x in m], how) for c, how in WORST.items()})
        rows.append(row)
    return rows


def _fmu_on_worker(blob: bytes) -> Path:
    """The FMU ``blob`` as a file on this machine (by its hash, written once)."""
    digest = hashlib.sha256(blob).hexdigest()[:24]
    folder = Path(tempfile.gettempdir()) / "cushion_clutch_fleet"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{digest}.fmu"
    if not path.is_file():
        tmp = folder / f"{digest}.{os.getpid()}.part"
        tmp.write_bytes(blob)
        os.replace(tmp, path)
    return path


def run_sample(pop: Population, seed: int, i: int, tcus: Sequence[str], blobs: dict, tables: dict) -> list[dict]:
    """:func:`sample_rows` on a Dask worker: the FMUs come as bytes; a failure names the worker."""
    try:
        fmus = {k: _fmu_on_worker(b) for k, b in blobs.items()}
        return sample_rows(pop, seed, i, tcus, fmus, tables)
    except Exception as exc:
        import platform
        try:
            from distributed import get_worker
            where = get_worker().address
        except (ImportError, ValueError):
            where = "no worker"
        raise RuntimeError(f"sample {i} failed on Dask worker {where} (host {platform.node()}, pid {os.getpid()}): "
                           f"{type(exc).__name__}: {exc}") from exc


@dataclass
class FleetRun:
    """What :func:`run_fleet` did."""

    out: Path
    rows: list
    summary: list
    ran: int
    kept: int
    wall_s: float
    workers: int
    launches_run: int
    paths: list

    @property
    def launches_per_s_per_core(self) -> float:
        """Simulated launches (every TCU's) per second of wall time per worker slot, 1/s (NaN: none ran)."""
        if not self.launches_run or self.wall_s <= 0:
            return math.nan
        return self.launches_run / self.wall_s / self.workers


def _identity(pop: Population, seed: int, tcus: Sequence[str], tables: Path) -> dict:
    from ... import __version__
    return {"population": pop.name, "population_sha256": hashlib.sha256(pop.source.encode()).hexdigest(),
            "scenario": pop.scenario.name, "seed": int(seed), "tcus": list(tcus), "tables": str(Path(tables).name),
            "version": __version__}


def build_inputs(pop: Population, tables: Path, stage: Path, backend: str = "native") -> tuple[dict, dict]:
    """Per spring set: the plant FMU (built into ``stage``) and the TCUs' table."""
    from ...model import load_table
    from ..plant.build import build_plant_fmu
    from .population import Sample

    fmus, tcu_tables = {}, {}
    for spring in pop.springs:
        probe = Sample(0, 1000.0, False, 0.0, 0.0, 20.0, 20.0, 0.5, 60.0, 0.0, 0.0, spring.name, 1, 1)
        sc = sample_scenario(pop, probe)
        fmus[spring.name] = build_plant_fmu(Path(tables), sc, stage / spring.name / "CushionClutch.fmu",
                                            backend=backend)
        tcu_tables[spring.name] = load_table(sc.tables_path("tcu") or Path(tables))
    return fmus, tcu_tables


def run_fleet(pop: Population, tables: Path, out: Path, samples: int, tcus: Sequence[str], seed: int = 0, *,
              scheduler=None, jobs: int | None = None, serial: bool = False, backend: str = "native",
              progress: Callable[[int, int], None] | None = None) -> FleetRun:
    """Run ``samples`` samples (0 .. samples-1) of ``pop`` with each of ``tcus`` and write the outputs to ``out``.

    ``serial``: in this process, one sample after the other (no Dask); else on ``scheduler`` (an address or a
    ``distributed.Client``) or a LocalCluster of ``jobs`` single-threaded workers. ``progress(done, total)``
    as samples finish (kept ones counted at the start).

    Raises
    ------
    ParameterError
        ``out`` holds a fleet run of another population, seed, TCU set or table set.
    ClusterError
        Samples failed (each named with its worker) or every worker was lost; the finished ones are kept.
    """
    from ..tcu.controller import VARIANTS

    bad = [t for t in tcus if t not in VARIANTS]
    if bad or not tcus:
        raise ParameterError([f"--tcus {','.join(tcus)}: unknown {', '.join(bad) or 'none given'} "
                              f"(allowed: {', '.join(VARIANTS)})"])
    if len(set(tcus)) != len(tcus):
        raise ParameterError([f"--tcus {','.join(tcus)}: a TCU named twice"])
    if not 1 <= samples <= 10 ** 6:
        raise ParameterError([f"--samples {samples}: must be in [1, 1000000]"])
    out = Path(out)
    parts = out / PARTS
    parts.mkdir(parents=True, exist_ok=True)
    ident = _identity(pop, seed, tcus, tables)
    run_file = out / RUN_FILE
    if run_file.is_file():
        old = json.loads(run_file.read_text()).get("identity", {})
        diff = sorted(k for k in ident if old.get(k) != ident[k])
        if diff:
            raise ParameterError([f"--out {out} holds a fleet run with other {', '.join(diff)} "
                                  f"({', '.join(f'{k}={old.get(k)!r}' for k in diff)}); give another --out"])
    run_file.write_text(json.dumps({"identity": ident}, indent=1))
    done = {i for i in range(samples) if (parts / f"sample_{i:06d}.json").is_file()}
    todo = [i for i in range(samples) if i not in done]
    if progress:
        progress(len(done), samples)
    failures: list[str] = []
    finished = [len(done)]

    def keep(i: int, rows, exc) -> None:
        if exc is not None:
            failures.append(str(exc) if "failed on Dask worker" in str(exc) else f"sample {i}: {exc}")
            return
        tmp = parts / f"sample_{i:06d}.json.part"
        tmp.write_text(json.dumps(rows))
        os.replace(tmp, parts / f"sample_{i:06d}.json")
        finished[0] += 1
        if progress:
            progress(finished[0], samples)

    workers = 1
    start = time.perf_counter()
    if todo:
        fmus, tcu_tables = build_inputs(pop, tables, out / "fleet_fmu", backend)
        start = time.perf_counter()
        if serial:
            for i in todo:
                try:
                    rows = sample_rows(pop, seed, i, tcus, fmus, tcu_tables)
                except Exception as exc:  # noqa: BLE001 - collected and raised with the sample named
                    keep(i, None, exc)
                else:
                    keep(i, rows, None)
        else:
            from ...fe.cluster import open_cluster, watch
            with open_cluster(scheduler, jobs, need_ccx=False) as (client, info):
                workers = info.slots
                start = time.perf_counter()
                blobs = {k: client.scatter(Path(p).read_bytes(), broadcast=True) for k, p in fmus.items()}
                shipped = client.scatter(tcu_tables, broadcast=True)
                popf = client.scatter(pop, broadcast=True)
                futures = {client.submit(run_sample, popf, seed, i, tuple(tcus), blobs, shipped, pure=False): i
                           for i in todo}
                watch(client, info, futures, keep, what="sample(s)",
                      resume=f"finished samples are kept in {parts}, a rerun resumes")
    wall = time.perf_counter() - start
    if failures:
        raise ClusterError(f"{len(failures)} of {len(todo)} sample(s) failed (the {finished[0]} finished are kept in "
                           f"{parts}; a rerun resumes):\n  - " + "\n  - ".join(failures[:20])
                           + ("" if len(failures) <= 20 else f"\n  - ... and {len(failures) - 20} more"))
    rows = [r for i in range(samples) for r in json.loads((parts / f"sample_{i:06d}.json").read_text())]
    ran = len(todo)
    launches_run = sum(r["launches"] for r in rows if r["sample"] in set(todo))
    summary = summarise(rows, tcus)
    paths = [write_samples(rows, out / SAMPLES_FILE), write_summary(summary, out / SUMMARY_FILE)]
    paths.append(plot_fleet(rows, tcus, out / PLOT_FILE, f"population '{pop.name}', {samples} samples, seed {seed}"))
    res = FleetRun(out, rows, summary, ran, len(done), wall, workers, launches_run, paths)
    run_file.write_text(json.dumps({
        "identity": ident, "samples": samples, "ran": ran, "kept": len(done), "workers": workers,
        "mode": "serial" if serial else "dask", "wall_s": wall, "launches_run": launches_run,
        "launches_per_s_per_core": res.launches_per_s_per_core, "load_average": list(os.getloadavg())},
        indent=1))
    paths.append(run_file)
    return res


def summarise(rows: list[dict], tcus: Sequence[str]) -> list[dict]:
    """Per TCU and metric (:data:`WORST`, plus ``lockups``): P50, P95, P99 and max over the samples."""
    out = []
    for name in tcus:
        mine = [r for r in rows if r["tcu"] == name]
        for metric in ("lockups", *WORST):
            vals = np.array([float(r[metric]) for r in mine], dtype=float)
            vals = vals[np.isfinite(vals)]
            if vals.size:
                p = np.percentile(vals, PERCENTILES)
                out.append({"tcu": name, "metric": metric, "p50": float(p[0]), "p95": float(p[1]),
                            "p99": float(p[2]), "max": float(vals.max())})
            else:
                out.append({"tcu": name, "metric": metric, "p50": math.nan, "p95": math.nan, "p99": math.nan,
                            "max": math.nan})
    return out


def write_summary(summary: list[dict], path: Path) -> Path:
    import csv
    tmp = path.with_suffix(".part")
    with open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["tcu", "metric", "p50", "p95", "p99", "max"])
        w.writeheader()
        for r in summary:
            w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in r.items()})
    os.replace(tmp, path)
    return path


def write_samples(rows: list[dict], path: Path) -> Path:
    """``fleet_samples.parquet``: the rows in :data:`COLUMNS` order (pyarrow)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols = {}
    for c in COLUMNS:
        vals = [r[c] for r in rows]
        if c in ("tcu", "spring"):
            cols[c] = pa.array(vals, pa.string())
        elif c == "trailer":
            cols[c] = pa.array([bool(v) for v in vals], pa.bool_())
        elif c in ("sample", "sensor_seed", "tcu_seed", "launches", "lockups") or WORST.get(c) == "count":
            cols[c] = pa.array([int(v) for v in vals], pa.int64())
        else:
            cols[c] = pa.array([float(v) for v in vals], pa.float64())
    tmp = path.with_suffix(".part")
    pq.write_table(pa.table(cols), tmp)
    os.replace(tmp, path)
    return path


def read_samples(path: Path) -> list[dict]:
    """The rows of a ``fleet_samples.parquet``."""
    import pyarrow.parquet as pq
    return pq.read_table(path).to_pylist()


def plot_fleet(rows: list[dict], tcus: Sequence[str], png: Path, title: str) -> Path:
    """CDF of ``characteristic_error_max_Nm`` per TCU; the error against ambient temperature and facing wear."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    metric = "characteristic_error_max_Nm"
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    colours = {"naive": "tab:red", "production": "tab:blue", "aware_estimated": "tab:green", "aware": "tab:olive",
               "adaptive": "tab:orange", "adaptive_aware_estimated": "tab:purple"}
    for name in tcus:
        mine = [r for r in rows if r["tcu"] == name and math.isfinite(r[metric])]
        if not mine:
            continue
        e = np.sort([r[metric] for r in mine])
        p = np.arange(1, e.size + 1) / e.size
        c = colours.get(name)
        p99 = np.percentile(e, 99)
        axes[0].step(e, p, where="post", color=c, label=f"{name} (P99 {p99:.2f} N·m, n = {e.size})")
        axes[1].scatter([r["ambient_degC"] for r in mine], [r[metric] for r in mine], s=8, color=c, alpha=0.6,
                        label=name)
        axes[2].scatter([r["facing_wear_m"] * 1e3 for r in mine], [r[metric] for r in mine], s=8, color=c,
                        alpha=0.6, label=name)
    axes[0].axvline(ERROR_BAR_NM, color="k", ls=":", lw=1)
    axes[0].text(ERROR_BAR_NM, 0.5, " 9.4 N·m (3 % of 312 N·m)", fontsize=8, rotation=90, va="center",
                 transform=axes[0].get_xaxis_transform())
    for y in (0.95, 0.99):
        axes[0].axhline(y, color="grey", lw=0.5, ls="--")
        axes[0].text(0.01, y, f"P{round(y * 100)}", fontsize=7, va="bottom", transform=axes[0].get_yaxis_transform())
    axes[0].set_ylim(0.0, 1.02)
    for ax in axes:                    # the TCUs' errors differ by orders of magnitude
        ax.set_xscale("log") if ax is axes[0] else ax.set_yscale("log")
    axes[0].set_xlabel("characteristic error, worst of a sample's launches [N·m] (log)")
    axes[0].set_ylabel("fraction of samples")
    axes[0].set_title("CDF of the characteristic error per TCU")
    axes[1].set_xlabel("ambient temperature [°C]")
    axes[1].set_title("error against ambient")
    axes[2].set_xlabel("facing wear [mm]")
    axes[2].set_title("error against facing wear (TCUs believe new)")
    for ax in axes[1:]:
        ax.set_ylabel("characteristic error [N·m] (log)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return png
