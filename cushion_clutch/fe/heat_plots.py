"""Plot of ``cushion-clutch heat-path``: the FE's theta_cs against the fitted ODE and the paper's."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import plt
from .heat_fit import PAPER, first_order, two_lags


def plot_heat_path(case, ident: dict, hp, path: Path) -> None:
    """theta_cm, theta_cs (FE), the fitted first-order ODE, the two-lag fit and the paper's ODE, with errors."""
    t, th_a = case.t_s, hp.ambient_degC
    fit = first_order(case.theta_cm_degC, case.dt_s, th_a, ident["tau_s"], ident["gain"])
    tl = ident["two_lags"]
    fit2 = two_lags(case.theta_cm_degC, case.dt_s, th_a, tl["gain_1"], tl["tau_1_s"], tl["gain_2"], tl["tau_2_s"])
    p_tau = PAPER["C_J_per_K"] / (PAPER["U_W_per_K"] + PAPER["H_W_per_K"])
    p_gain = PAPER["U_W_per_K"] / (PAPER["U_W_per_K"] + PAPER["H_W_per_K"])
    paper = first_order(case.theta_cm_degC, case.dt_s, th_a, p_tau, p_gain)
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    ax.plot(t, case.theta_cm_degC, color="tab:red", lw=1.0, label="θ_cm: FE facing mean")
    ax.plot(t, case.theta_carrier_degC, color="tab:gray", lw=1.0, label="carrier mean (FE)")
    ax.plot(t, case.theta_cs_degC, color="k", lw=2.2, label="θ_cs: FE paddle mean")
    ax.plot(t, fit, color="tab:blue", lw=1.2, ls="--",
            label=f"ODE fitted to the FE: U {ident['U_W_per_K']:.3g} W/K, H {ident['H_W_per_K']:.3g} W/K, "
                  f"C {ident['C_J_per_K']:.3g} J/K (τ {ident['tau_s']:.3g} s)")
    ax.plot(t, fit2, color="tab:green", lw=1.0, ls=":",
            label=f"two lags: τ {tl['tau_1_s']:.3g} s and {tl['tau_2_s']:.3g} s")
    ax.plot(t, paper, color="tab:orange", lw=1.0, ls="-.",
            label=f"paper's ODE: U {PAPER['U_W_per_K']} W/K, H {PAPER['H_W_per_K']} W/K, C {PAPER['C_J_per_K']} J/K "
                  f"(τ {p_tau:.2g} s)")
    ax.set_ylabel("temperature [°C]")
    ax.set_title(f"Cushion-spring heat path: disc-sector FE (mesh {case.element_size_m * 1e3:g} mm, "
                 f"{case.n_nodes} nodes), same θ_cm driving every ODE")
    ax.legend(fontsize=7.5, loc="upper right")
    ax.grid(alpha=0.3)
    ax2.plot(t, fit - case.theta_cs_degC, color="tab:blue", lw=1.0,
             label=f"fitted ODE − FE (RMS {ident['ode_rms_error_K']:.3g} K, max {ident['ode_max_error_K']:.3g} K)")
    ax2.plot(t, fit2 - case.theta_cs_degC, color="tab:green", lw=1.0,
             label=f"two lags − FE (RMS {tl['rms_error_K']:.3g} K)")
    ax2.axhline(0.0, color="k", lw=0.5)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("error [K]")
    ax2.legend(fontsize=7.5, loc="upper right")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    np.seterr(all="warn")
