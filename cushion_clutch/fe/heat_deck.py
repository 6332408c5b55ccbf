"""CalculiX deck of the disc-sector transient heat transfer (DC3D8 bricks, *HEAT TRANSFER, DIRECT).

Reads a :class:`~cushion_clutch.fe.heat_mesh.HeatMesh` (nodes, bricks,
per-element properties, named face groups) and a heating history
(:class:`Schedule`); knows nothing of the geometry. Materials: one per distinct
(conductivity, density, specific heat) after rounding the conductivity to
0.5 % (log bins, bin value = the members' volume-weighted mean, so the total
conductance of the interface layers is kept). SI units throughout, temperatures
in degC.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .heat_mesh import HeatMesh

#: ccx element type: eight-node heat-transfer brick
ELEMENT_TYPE = "DC3D8"


@dataclass(frozen=True)
class Phase:
    """A stretch of time solved with fixed increments.

    Attributes
    ----------
    end_s : float
        Total time at its end, s.
    increments : int
        Equal increments in it.
    output_every : int
        Temperatures printed every this many increments (the last increment always).
    """

    end_s: float
    increments: int
    output_every: int


@dataclass(frozen=True)
class Schedule:
    """The heating history and the time stepping.

    Attributes
    ----------
    flux_times_s, flux_W_per_m2 : tuple of float
        Friction-surface heat flux (piecewise linear in total time), W/m^2.
    phases : tuple of Phase
        Consecutive stretches from t = 0.
    ambient_degC : float
        Sink of every film and the initial temperature, degC.
    """

    flux_times_s: tuple[float, ...]
    flux_W_per_m2: tuple[float, ...]
    phases: tuple[Phase, ...]
    ambient_degC: float

    def flux(self, t_s: np.ndarray) -> np.ndarray:
        """Flux at total times ``t_s``, W/m^2 (as ccx interpolates the amplitude)."""
        return np.interp(t_s, self.flux_times_s, self.flux_W_per_m2)

    def increment_times(self) -> np.ndarray:
        """End time of every increment, s."""
        out, start = [], 0.0
        for ph in self.phases:
            out.append(start + (ph.end_s - start) * np.arange(1, ph.increments + 1) / ph.increments)
            start = ph.end_s
        return np.concatenate(out)


def materials(mesh: HeatMesh, rel_bin: float = 0.005) -> tuple[np.ndarray, list[tuple[float, float, float]]]:
    """Material index of every element and the materials (k, rho, c).

    Conductivities are grouped in log bins of ``rel_bin`` together with equal
    density and specific heat; a bin's conductivity is its members' volume-weighted mean.
    """
    k, rho, c, v = (mesh.conductivity_W_per_m_K, mesh.density_kg_m3, mesh.specific_heat_J_per_kg_K,
                    mesh.volume_m3)
    key = np.stack([np.round(np.log(k) / rel_bin), np.round(rho, 6), np.round(c, 6)], axis=1)
    uniq, index = np.unique(key, axis=0, return_inverse=True)
    index = index.ravel()
    mats = []
    for m in range(len(uniq)):
        sel = index == m
        mats.append((float(np.sum(k[sel] * v[sel]) / np.sum(v[sel])), float(rho[sel][0]), float(c[sel][0])))
    return index, mats


def _lines(rows, fmt: str) -> str:
    return "".join(fmt % tuple(r) for r in rows)


def write_deck(mesh: HeatMesh, schedule: Schedule, films_W_per_m2_K: dict[str, float]) -> str:
    """The ``.inp`` text: bricks, materials, initial temperature, flux on FRICTION, films, phases.

    Parameters
    ----------
    mesh : HeatMesh
        The sector.
    schedule : Schedule
        Flux history and time stepping.
    films_W_per_m2_K : dict
        Film coefficient of each face group (``FRICTION``, ``HUB``, ``CONVECTION``), W/(m^2 K).
    """
    idx, mats = materials(mesh)
    out = ["*HEADING\ncushion-clutch heat-path: disc sector, transient heat transfer (SI, degC)\n", "*NODE, NSET=NALL\n"]
    out.append(_lines(np.column_stack([np.arange(1, len(mesh.nodes) + 1), mesh.nodes]), "%d,%.9e,%.9e,%.9e\n"))
    for m in range(len(mats)):
        sel = np.flatnonzero(idx == m)
        out.append(f"*ELEMENT, TYPE={ELEMENT_TYPE}, ELSET=M{m}\n")
        out.append(_lines(np.column_stack([sel + 1, mesh.elements[sel] + 1]), "%d" + ",%d" * 8 + "\n"))
    for m, (k, rho, c) in enumerate(mats):
        out.append(f"*MATERIAL, NAME=MAT{m}\n*CONDUCTIVITY\n{k:.9e}\n*DENSITY\n{rho:.9e}\n"
                   f"*SPECIFIC HEAT\n{c:.9e}\n*SOLID SECTION, ELSET=M{m}, MATERIAL=MAT{m}\n")
    out.append(f"*INITIAL CONDITIONS, TYPE=TEMPERATURE\nNALL, {schedule.ambient_degC:.6f}\n")
    out.append("*AMPLITUDE, NAME=AQ, TIME=TOTAL TIME\n")
    out.append(_lines(np.column_stack([schedule.flux_times_s, schedule.flux_W_per_m2]), "%.9e,%.9e\n"))
    start = 0.0
    for n, ph in enumerate(schedule.phases):
        dt = (ph.end_s - start) / ph.increments
        out.append(f"*STEP, INC={ph.increments + 10}, AMPLITUDE=STEP\n*HEAT TRANSFER, DIRECT\n"
                   f"{dt:.9e},{ph.end_s - start:.9e}\n")
        if n == 0:
            fr = mesh.faces["FRICTION"]
            out.append("*DFLUX, AMPLITUDE=AQ\n")
            out.append(_lines(np.column_stack([fr[:, 0] + 1, fr[:, 1]]), "%d,S%d,1.0\n"))
            for name, h in films_W_per_m2_K.items():
                fc = mesh.faces.get(name, np.zeros((0, 2), dtype=int))
                if not len(fc):
                    continue
                out.append("*FILM\n")
                out.append(_lines(np.column_stack([fc[:, 0] + 1, fc[:, 1]]),
                                  f"%d,F%d,{schedule.ambient_degC:.6f},{h:.9e}\n"))
        out.append(f"*NODE PRINT, NSET=NALL, FREQUENCY={ph.output_every}\nNT\n*END STEP\n")
        start = ph.end_s
    return "".join(out)


def parse_temperatures(dat_text: str, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and nodal temperatures (frames, nodes) of every ``NT`` block of a ``.dat`` file."""
    times, frames = [], []
    blocks = dat_text.split(" temperatures for set ")[1:]
    for b in blocks:
        head, _, body = b.partition("\n")
        times.append(float(head.split("time")[-1]))
        vals = np.array(body.split(), dtype=float)
        vals = vals[: 2 * n_nodes].reshape(-1, 2)
        if len(vals) != n_nodes:
            raise ValueError(f"ccx printed {len(vals)} of {n_nodes} node temperatures at t = {times[-1]:g} s")
        t = np.empty(n_nodes)
        t[vals[:, 0].astype(int) - 1] = vals[:, 1]
        frames.append(t)
    return np.array(times), np.array(frames)


def launch_schedule(n_launches: int, period_s: float, slip_s: float, peak_flux_W_per_m2: float, cooldown_s: float,
                    ambient_degC: float, dt_s: float) -> Schedule:
    """Launches every ``period_s``: the flux falls linearly from its peak to 0 over the slip (the slip power
    of a launch at constant torque), then nothing; then ``cooldown_s``.

    Increments of about ``dt_s`` during the slip, twice that to 20 s after it, four times that to the
    next launch, eight times in the cool-down; temperatures printed at every increment. ccx integrates in
    time with backward Euler and takes a load at the end of each increment, so the amplitude's points sit
    at the increment ends and carry the slip power at each increment's middle: every increment receives
    exactly the heat the linear ramp delivers in it.
    """
    times, flux, phases = [0.0], [0.0], []
    start = 0.0
    n_slip = max(1, math.ceil(slip_s / dt_s - 1e-9))

    def phase(end: float, n: int) -> None:
        nonlocal start
        phases.append(Phase(end, n, 1))
        start = end

    def span(end: float, dt: float) -> None:
        phase(end, max(1, math.ceil((end - start) / dt - 1e-9)))

    for n in range(n_launches):
        t0 = n * period_s
        if t0 > 0.0:
            times.append(t0)
            flux.append(0.0)
        for k in range(1, n_slip + 1):
            times.append(t0 + slip_s * k / n_slip)
            flux.append(peak_flux_W_per_m2 * (1.0 - (k - 0.5) / n_slip))
        phase(t0 + slip_s, n_slip)
        span(t0 + slip_s + 20.0, 2 * dt_s)
        times.append(phases[-1].end_s - 20.0 + 20.0 / phases[-1].increments)
        flux.append(0.0)
        span(t0 + period_s, 4 * dt_s)
    end = n_launches * period_s + cooldown_s
    times.append(end)
    flux.append(0.0)
    span(end, 8 * dt_s)
    return Schedule(tuple(times), tuple(flux), tuple(phases), ambient_degC)
