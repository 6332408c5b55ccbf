"""Outputs of a calibration: the calibrated TOML, a text report and a Fig. 9 style PNG."""
from __future__ import annotations

from pathlib import Path

from ...config import toml_document
from ...plotting import finish_figure, plt
from .calibrate import Calibration
from ..params import SpringParams


def params_toml(params: SpringParams, header: str = "") -> str:
    """A spring parameter set as TOML text that :func:`load_params` reads back unchanged."""
    return toml_document(params.to_dict(), header)


def report_text(cal: Calibration) -> str:
    """Human-readable calibration report."""
    m = cal.measured
    lines = [f"calibration to {len(m.u_m)} measured points ({m.basis} force), FE at "
             f"{cal.params.material.reference_temperature_degC:g} degC, mesh "
             f"{cal.params.mesh.element_size_m * 1e3:g} mm {cal.params.mesh.element_type}",
             f"{'parameter':<28}{'start':>12}{'fitted':>12}{'1-sigma':>11}{'dlnF/dlnp':>11}"]
    for n, a, b, s, k in zip(cal.names, cal.start, cal.values, cal.std, cal.sensitivity):
        lines.append(f"{n:<28}{a:>12.5g}{b:>12.5g}{s:>11.2g}{k:>11.2f}")
    lines += [f"RMS error {cal.rms_N:.2f} N ({cal.rms_pct:.2f} % of the largest measured force), "
              f"max error {cal.max_N:.2f} N ({cal.max_pct:.2f} %)",
              f"FE cases {cal.fe_cases} ({cal.cached_cases} from the cache), wall time "
              f"{cal.wall_time_s:.1f} s; optimiser: {cal.message}"]
    return "\n".join(lines) + "\n"


def plot_calibration(cal: Calibration, path: Path, title: str = "") -> Path:
    """FE (start and calibrated) against the measured curve, like the paper's Fig. 9."""
    m = cal.measured
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(m.u_m * 1e3, m.force_N, "o", ms=4, mfc="none", color="k", label="measured")
    ax.plot(m.u_m * 1e3, cal.fe_start_N, "--", color="tab:gray", label="FE, start parameters")
    ax.plot(m.u_m * 1e3, cal.fe_fit_N, "-", color="tab:red",
            label=f"FE, calibrated (RMS {cal.rms_pct:.1f} %)")
    ax.set(xlabel="compression from the kiss point u [mm]",
           ylabel=f"force of {'one paddle pair' if m.basis == 'pair' else 'the whole spring'} [N]",
           title=title or "Cushion spring: FE against measurement")
    return finish_figure(fig, ax, path)
