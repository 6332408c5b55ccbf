"""Repeated clutch engagements driven through the FMU with fmpy (paper Figs. 10 and 12).

The facing temperature theta_cm comes from a lumped facing model heated by
the slip power of each engagement (period 60 s as in the paper):

    C_f d(theta_cm)/dt = P(t) - G_f (theta_cm - theta_a),

with P = P_slip during the first ``slip_time_s`` of every period and 0 after;
solved exactly piecewise. The defaults heat the facings into the paper's
200-300 degC band within about ten engagements.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...model import KELVIN, ClutchParameters, SpringTable, outputs
from ...model.clutch_model import OMEGA_SLIP_START


@dataclass(frozen=True)
class EngagementCycle:
    """Repeated engagements: facing heat input and bearing stroke.

    Attributes
    ----------
    period_s : float
        Time between engagement starts, s.
    slip_time_s : float
        Slipping phase of each engagement, s (bearing ramps to closed).
    closed_time_s : float
        Time held closed after the slip phase before opening, s.
    slip_power_W : float
        Mean slip power into the facings while slipping, W.
    facing_capacity_J_per_K : float
        Heat capacity of the facings and their plates, J/K.
    facing_loss_W_per_K : float
        Heat loss coefficient of the facings to ambient, W/K.
    x_to_closed_m : float
        Bearing position when closed, m.
    theta_a_K : float
        Ambient temperature, K.
    """

    period_s: float = 60.0
    slip_time_s: float = 2.0
    closed_time_s: float = 20.0
    slip_power_W: float = 13.8e3
    facing_capacity_J_per_K: float = 500.0
    facing_loss_W_per_K: float = 2.0
    x_to_closed_m: float = 0.008
    theta_a_K: float = 293.15

    def facing_temperature(self, t: np.ndarray) -> np.ndarray:
        """theta_cm(t) in K from the exact piecewise solution, starting at ambient."""
        t = np.asarray(t, float)
        tau = self.facing_capacity_J_per_K / self.facing_loss_W_per_K
        rise_hot = self.slip_power_W / self.facing_loss_W_per_K      # steady rise while slipping
        out = np.empty_like(t)
        theta = 0.0                  # rise above ambient at the start of the current phase
        phase_start, k = 0.0, 0
        order = np.argsort(t)
        for i in order:
            ti = t[i]
            while True:
                hot_end = k * self.period_s + self.slip_time_s
                cold_end = (k + 1) * self.period_s
                if ti <= hot_end:
                    out[i] = rise_hot + (theta - rise_hot) * math.exp(-(ti - phase_start) / tau)
                    break
                if phase_start < hot_end:
                    theta = rise_hot + (theta - rise_hot) * math.exp(-(hot_end - phase_start) / tau)
                    phase_start = hot_end
                if ti <= cold_end:
                    out[i] = theta * math.exp(-(ti - phase_start) / tau)
                    break
                theta *= math.exp(-(cold_end - phase_start) / tau)
                phase_start, k = cold_end, k + 1
        return out + self.theta_a_K

    def bearing_position(self, t: np.ndarray) -> np.ndarray:
        """x_to(t) in m: ramp to closed over the slip phase, hold, then open."""
        tc = np.mod(np.asarray(t, float), self.period_s)
        ramp = np.clip(tc / self.slip_time_s, 0.0, 1.0) * self.x_to_closed_m
        return np.where(tc <= self.slip_time_s + self.closed_time_s, ramp, 0.0)


def simulate(fmu: Path, cycle: EngagementCycle = EngagementCycle(), n_engagements: int = 12,
             step_s: float = 0.1, start_values: dict | None = None) -> np.ndarray:
    """Simulate the FMU over repeated engagements with fmpy.

    Returns a structured array with ``time``, the inputs and the outputs.
    """
    from fmpy import simulate_fmu

    from ...fmpy_logger import restore_fmpy_logger

    stop = n_engagements * cycle.period_s
    t = np.arange(0.0, stop + step_s / 2, step_s)
    # every input given (omega_slip at its start value), so fmpy does not warn about a missing one
    inputs = np.zeros(len(t), dtype=[("time", float), ("x_to", float), ("theta_cm", float), ("omega_slip", float)])
    inputs["time"], inputs["x_to"], inputs["theta_cm"] = t, cycle.bearing_position(t), cycle.facing_temperature(t)
    inputs["omega_slip"] = OMEGA_SLIP_START
    restore_fmpy_logger()       # fmpy's default logger: never one freed by an earlier run in this process
    res = simulate_fmu(str(fmu), start_time=0.0, stop_time=stop, output_interval=step_s,
                       input=inputs, start_values=start_values or {},
                       output=["x_to", "theta_cm", "torque", "force", "theta_cs", "u_f", "x_kiss"])
    return res


def plot_engagements(res: np.ndarray, path: Path) -> Path:
    """theta_cm and theta_cs over repeated engagements (paper Fig. 10), and the torque."""
    import matplotlib.pyplot as plt

    from ...plotting import finish_figure

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.plot(res["time"], res["theta_cm"] - KELVIN, label="facing θ_cm")
    a1.plot(res["time"], res["theta_cs"] - KELVIN, label="cushion spring θ_cs")
    a1.set(ylabel="temperature [°C]", title="Repeated engagements, 60 s period (FMU via fmpy)")
    a1.legend()
    a2.plot(res["time"], res["torque"], color="C2")
    a2.set(xlabel="time [s]", ylabel="clutch torque [N·m]")
    return finish_figure(fig, [a1, a2], path, legend=False)


def plot_torque_characteristic(table: SpringTable, path: Path, p: ClutchParameters = ClutchParameters()) -> Path:
    """T(x_to) at each table temperature (paper Fig. 12), from the shared model."""
    import matplotlib.pyplot as plt

    from ...plotting import finish_figure

    x = np.linspace(p.x_kiss_ref - 1.0e-3, p.x_kiss_ref + p.lever_ratio * 1.45e-3, 600)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for t in table.theta_degC:
        ax.plot(x * 1e3, [outputs(xi, t + KELVIN, table, p).torque for xi in x], label=f"{t:g} °C")
    ax.axvline(p.x_kiss_ref * 1e3, color="k", lw=0.8, ls=":")
    ax.set(xlabel="throwout-bearing position x_to [mm]", ylabel="clutch torque T [N·m]",
           title="Clutch torque characteristic vs cushion-spring temperature")
    return finish_figure(fig, ax, path)


def plot_thermal_step(path: Path, p: ClutchParameters = ClutchParameters()) -> Path:
    """Step response of the python-control thermal model to a 100 K facing step."""
    import control
    import matplotlib.pyplot as plt

    from ...plotting import finish_figure

    from ...model import thermal_system

    sys = thermal_system(p)
    t = np.linspace(0.0, 6 * p.C / (p.U + p.H), 400)
    resp = control.step_response(sys, t, input=0)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(resp.time, 100.0 * np.squeeze(resp.outputs), label="θ_cs rise")
    ax.axhline(100.0 * p.U / (p.U + p.H), ls="--", color="k", lw=0.8, label="U/(U+H) × 100 K")
    ax.axvline(p.C / (p.U + p.H), ls=":", color="k", lw=0.8, label="τ = C/(U+H)")
    ax.set(xlabel="time [s]", ylabel="temperature rise [K]",
           title="Cushion-spring response to a 100 K facing step")
    return finish_figure(fig, ax, path)
