"""Outputs of a calibration: the calibrated TOML, a text report and a Fig. 9 style PNG."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...config import toml_document
from ...plotting import finish_figure, plt
from .calibrate import Calibration
from ..params import SpringParams


def params_toml(params: SpringParams, header: str = "") -> str:
    """A spring parameter set as TOML text that :func:`load_params` reads back unchanged."""
    return toml_document(params.to_dict(), header)


def calibrated_params(cal: Calibration, name: str) -> SpringParams:
    """The calibrated spring under its own ``name``, described by what it was fitted to."""
    curves = ", ".join(f"{m.source or 'a curve given in code'} ({m.theta_degC:g} degC, {len(m.u_m)} points)"
                       for m in cal.measured)
    fitted = ", ".join(f"{n} = {v:.6g}" for n, v in zip(cal.names, cal.values))
    return cal.params.replace(name=name, description=(
        f"'{cal.params.name}' calibrated by cushion-clutch calibrate to {curves}: {fitted}; RMS error "
        f"{cal.rms_pct:.2f} % of the largest measured force"))


def report_text(cal: Calibration) -> str:
    """Human-readable calibration report, ending with every warning (bound, identifiability, residual).

    The 1-sigma is the total (noise and mesh terms in quadrature, :mod:`.calibrate`); its terms follow
    as % of the fitted value: ``noise`` (linearised, x ``profile`` where the FE's misfit is flatter than
    linear) and ``mesh`` (the move to a finer mesh). ``dlnF/dlnp`` is the force-weighted mean
    sensitivity, ``RMS %/%`` the RMS change of the forces per 1 % of the parameter.
    """
    curves = ", ".join(f"{len(m.u_m)} points at {m.theta_degC:g} degC" for m in cal.measured)
    n = len(cal.names)
    noise = cal.std_noise if cal.std_noise is not None else np.full(n, np.nan)
    factor = cal.profile_factor if cal.profile_factor is not None else np.full(n, np.nan)
    mesh = cal.std_mesh if cal.std_mesh is not None else np.full(n, np.nan)
    sens = cal.sensitivity_rms_pct if cal.sensitivity_rms_pct is not None else np.full(n, np.nan)
    lines = [f"calibration to {curves} ({cal.measured[0].basis} force), mesh "
             f"{cal.params.mesh.element_size_m * 1e3:g} mm {cal.params.mesh.element_type}",
             f"{'parameter':<32}{'start':>11}{'fitted':>12}{'1-sigma':>10}{'1-sigma %':>10}{'noise %':>9}"
             f"{'profile':>8}{'mesh %':>8}{'dlnF/dlnp':>10}{'RMS %/%':>8}  bounds"]
    for i, (nm, a, b, s, k, (lo, hi)) in enumerate(zip(cal.names, cal.start, cal.values, cal.std,
                                                       cal.sensitivity, cal.bounds)):
        pct = 100 / abs(b) if b else float("inf")
        lines.append(f"{nm:<32}{a:>11.5g}{b:>12.5g}{s:>10.2g}{s * pct:>10.2f}{noise[i] * pct:>9.2f}"
                     f"{factor[i]:>8.2f}{mesh[i] * pct:>8.2f}{k:>10.2f}{sens[i]:>8.3f}  {lo:.5g}:{hi:.5g}")
    if n > 1:
        lines.append("correlation: " + "; ".join(
            f"{cal.names[i]} / {cal.names[j]} {cal.correlation[i, j]:+.3f}"
            for i in range(n) for j in range(i + 1, n)) + f"; condition number {cal.condition:.3g}")
    if cal.mesh_check_m is not None:
        lines.append(f"1-sigma = noise (x profile) and mesh in quadrature; mesh: the fitted values' linearised "
                     f"move to a {cal.mesh_check_m * 1e3:.3g} mm mesh")
    else:
        lines.append("1-sigma = noise (x profile) only: the mesh check was not run")
    for theta, h, sd, h0, h1 in cal.free_height or []:
        lines.append(f"free height at {theta:g} degC: measured {h * 1e3:.4f} +- {sd * 1e3:.4f} mm, FE start "
                     f"{h0 * 1e3:.4f} mm, FE fitted {h1 * 1e3:.4f} mm ({(h1 - h) / sd:+.2f} sigma)")
    lines += [f"RMS error {cal.rms_N:.2f} N ({cal.rms_pct:.2f} % of the largest measured force), "
              f"max error {cal.max_N:.2f} N ({cal.max_pct:.2f} %)",
              f"residual: {cal.runs} runs of one sign ({cal.runs_expected:.1f} expected for noise, runs test "
              f"p = {cal.runs_p:.2g}), lag-1 autocorrelation {cal.lag1_autocorrelation:+.2f}",
              f"FE cases {cal.fe_cases} ({cal.cached_cases} from the cache), wall time "
              f"{cal.wall_time_s:.1f} s; optimiser: {cal.message}"]
    warnings = cal.warnings()
    lines += [f"WARNING: {w}" for w in warnings] or ["no parameter at a bound or unidentifiable; residual "
                                                     "consistent with noise"]
    return "\n".join(lines) + "\n"


def plot_calibration(cal: Calibration, path: Path, title: str = "") -> Path:
    """FE (start and calibrated) against the measured curves, like the paper's Fig. 9."""
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for i, (m, f0, f1) in enumerate(zip(cal.measured, cal.fe_start_N, cal.fe_fit_N)):
        order = np.argsort(m.u_m, kind="stable")
        u = m.u_m[order] * 1e3
        ax.plot(u, m.force_N[order], "o", ms=4, mfc="none", color=f"C{i}", label=f"measured, {m.theta_degC:g} degC")
        ax.plot(u, f0[order], "--", color=f"C{i}", alpha=0.5, label=f"FE start, {m.theta_degC:g} degC")
        ax.plot(u, f1[order], "-", color=f"C{i}", label=f"FE calibrated, {m.theta_degC:g} degC")
    fitted = "; ".join(f"{n.split('.')[-1]} {v:.4g} +- {sd / abs(v):.1%}" for n, v, sd in
                       zip(cal.names, cal.values, cal.std))
    heights = [f"free height {t:g} degC: measured {h * 1e3:.3f} +- {sd * 1e3:.3f} mm, FE {h1 * 1e3:.3f} mm"
               for t, h, sd, _, h1 in cal.free_height or []]
    # the curves rise to the upper right: the fit's numbers and the legend below them in the empty upper left
    lines = [f"fitted (1-sigma): {fitted}", *heights]
    ax.text(0.02, 0.98, "\n".join(lines), transform=ax.transAxes, va="top", ha="left", fontsize=7, color="0.2")
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, 0.97 - 0.045 * len(lines)), fontsize=8)
    ax.set(xlabel="compression from the reference kiss point u [mm]",
           ylabel=f"force of {'one paddle pair' if cal.measured[0].basis == 'pair' else 'the whole spring'} [N]",
           title=title or f"Cushion spring: FE against measurement (RMS {cal.rms_pct:.1f} %)")
    return finish_figure(fig, ax, path, legend=False)
