"""Thermal protection of the clutch by the TCU's facing-temperature estimate: warn, limit, inhibit.

Production TCUs estimate the clutch temperature largely to protect the facings
(Ford's DPS6 dual-clutch "hot mode": the clutch is engaged more quickly and the
engine torque reduced, the driver told "Transmission hot - wait", the clutches
disengaged above a calculated 300 degC; Eaton's Endurant "clutch abuse
protection": three severity levels, a dash warning, launches restricted until
the clutch has cooled). Here, by the estimated temperature ``theta`` of the friction
system of a TCU that has one: the hotter of its facings (their mean) and its hotter
metal friction surface (``aware``: the true ones; ``aware_estimated`` and
``adaptive_aware_estimated``: the observer's network; ``production``: the EKF's; the
``naive`` and ``adaptive`` TCUs know no temperature and cannot protect). The surface
counts because the friction is read there (issue 37: mu fades with it) and the damage
limit is the friction system's; on the facings alone the surface reached 372 degC in
``protection`` and a launch on ``fade``'s duty started on a surface too faded to hold
the engine and slipped for its whole pedal time:

====  ===========  =================================================================
level  name        when / what
====  ===========  =================================================================
0      ok          ``theta < warn_degC``
1      warn        ``theta >= warn_degC``: the driver is told (a message, the signal)
2      limit       ``theta >= limit_degC`` at a launch's start: slip energy limited, the
                   launch's engine-speed target lowered towards ``limit_engine_speed_rpm``
                   (the slip speed, and with it the slip power, falls with it), but no lower
                   than the speed at which the engine's torque at the pedal, less the
                   holding torque the TCU believes, still brings the car to lock-up by the
                   lock-up deadline (:meth:`.tcu.TcuController.limited_target_rpm`: a limit
                   that strands the launch keeps it slipping, which is heat); decided per
                   launch (switched within a launch, the speed controller pulled the
                   engine down: a 208 N.m torque spike)
3      inhibit     at a launch's start, ``theta >= inhibit_degC`` or ``theta`` plus the
                   largest rise of the estimate over a launch so far (to its slot's peak)
                   reaches ``damage_degC - estimate_error_K``: no launch (the driver holds
                   the brake) until ``theta < resume_degC`` and the rise check passes
====  ===========  =================================================================

Levels 1 and 2 fall back ``hysteresis_K`` below their threshold. A launch that is not inhibited locks up
(the launch controller closes what slip is left at ``tcu.lockup_deadline_s``); one the vehicle cannot make
at all (the engine's torque at the pedal below the grade's holding torque) is counted apart from the
stranded ones (``launch_possible``, ``stranded`` in the launch metrics).

**Thresholds and their source.** The seed paper (cushion-spring study, its
ref. [9]): after repeated engagements the facings reach 300-350 degC, and
above 350-400 degC the friction system suffers permanent damage. The damage
limit is the lower bound, 350 degC; inhibiting a launch from 310 degC leaves
room for the estimate's error and the next launch's rise (the rise is checked
too); limiting from 280 degC and warning from 250 degC give the driver two
steps before the car refuses to move. The lowered engine-speed target was
measured on the ``protection`` duty (3500 kg, 12 %, hard pedal): 1500 rpm
instead of the pedal's 1835 rpm cut the slip energy from 88 to 61 kJ per start;
a *higher* target raised it (3000 rpm: 128 kJ), the engine's extra torque does
not shorten a load-limited slip.
"""
from __future__ import annotations

from pathlib import Path

from ...model import KELVIN
from ..scenario.tcu_params import Protection

OK, WARN, LIMIT, INHIBIT = 0, 1, 2, 3
LEVEL_NAMES = ("ok", "warn", "limit", "inhibit")
#: what the driver is told on entering a level
MESSAGES = ("clutch temperature normal", "clutch hot: avoid repeated starts",
            "clutch hot: launches limited", "clutch overheated: wait, launch inhibited until it has cooled")


class ThermalProtection:
    """The protection state of one TCU; :meth:`update` every TCU period, :meth:`launch_start` per launch.

    Parameters
    ----------
    p : Protection
    """

    __slots__ = ("p", "level", "inhibited", "theta_start", "rise", "events", "peak", "slot_peak")

    def __init__(self, p: Protection):
        self.p = p
        self.level = OK
        self.inhibited = False
        self.theta_start = None
        #: the largest rise of the estimate over one launch so far, K
        self.rise = 0.0
        #: (time s, launch, level, message): what the driver was told
        self.events: list[tuple[float, int, int, str]] = []
        #: the highest estimate seen, K
        self.peak = 0.0
        #: the highest estimate since the last launch's start, K
        self.slot_peak = 0.0

    def _set(self, level: int, t: float, launch: int) -> None:
        if level != self.level:
            self.level = level
            self.events.append((t, launch, level, MESSAGES[level]))

    def launch_start(self, theta_K: float, t: float, launch: int) -> bool:
        """At a launch's start with the estimate ``theta_K`` (K): True if the launch is inhibited."""
        p = self.p
        th = theta_K - KELVIN
        if self.theta_start is not None and not self.inhibited:     # the last launch's rise: to its slot's peak
            self.rise = max(self.rise, self.slot_peak - self.theta_start)
        reaches = th + self.rise >= p.damage_degC - p.estimate_error_K
        if self.inhibited:
            self.inhibited = th >= p.resume_degC or reaches
        else:
            self.inhibited = th >= p.inhibit_degC or reaches
        self.theta_start = self.slot_peak = theta_K
        if self.inhibited:
            self._set(INHIBIT, t, launch)
        elif self.level == INHIBIT:
            self._set(self._graded(th), t, launch)
        return self.inhibited

    def launch_end(self, theta_K: float) -> None:
        """After a launch's slip: remember its rise of the estimate (K) for the next launch's check."""
        if self.theta_start is not None and not self.inhibited:
            self.rise = max(self.rise, theta_K - self.theta_start)

    def _graded(self, th: float) -> int:
        p, hy = self.p, self.p.hysteresis_K
        cur = self.level if self.level != INHIBIT else OK
        if th >= p.limit_degC or (cur >= LIMIT and th >= p.limit_degC - hy):
            return LIMIT
        if th >= p.warn_degC or (cur >= WARN and th >= p.warn_degC - hy):
            return WARN
        return OK

    def update(self, theta_K: float, t: float, launch: int) -> int:
        """Every TCU period: the level for the estimate ``theta_K`` (K); an inhibit holds for its launch."""
        self.peak = max(self.peak, theta_K)
        self.slot_peak = max(self.slot_peak, theta_K)
        if not self.inhibited:
            self._set(self._graded(theta_K - KELVIN), t, launch)
        return self.level


def plot_protection(out: Path, png: Path, tcus: tuple[str, ...] = ("naive", "aware", "production")) -> Path:
    """Plot a protected heavy-duty run from a ``cushion-clutch launch`` output folder ``out``: per TCU the
    plant's facing temperature, the TCU's estimate and its protection level, and the slip energy per launch.
    """
    import csv

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    p = Protection()
    fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=False)
    colours = {"naive": "tab:red", "production": "tab:blue", "aware": "tab:green"}
    for name in tcus:
        d = np.genfromtxt(out / f"launch_{name}.csv", delimiter=",", names=True)
        c = colours.get(name, None)
        axes[0].plot(d["time_s"] / 60, d["theta_cm_K"] - KELVIN, color=c, lw=1.0,
                     label=f"{name}: plant facings" + ("" if name != "naive" else " (no protection)"))
        if np.isfinite(d["theta_cm_tcu_K"]).any():
            axes[0].plot(d["time_s"] / 60, d["theta_cm_tcu_K"] - KELVIN, color=c, lw=1.0, ls="--",
                         label=f"{name}: its estimate")
        if d["protection_level"].max() > 0:
            axes[1].plot(d["time_s"] / 60, d["protection_level"], color=c, lw=1.2,
                         label=name + (" (the true temperature)" if name == "aware" else " (its estimate)"))
    for y, lab in ((p.warn_degC, "warn"), (p.limit_degC, "limit"), (p.inhibit_degC, "inhibit"),
                   (p.damage_degC, "damage (seed paper)")):
        axes[0].axhline(y, color="k", lw=0.6, ls=":")
        axes[0].text(axes[0].get_xlim()[1], y, " " + lab, fontsize=8, va="center")
    axes[0].set_ylabel("facing temperature [degC]")
    axes[0].set_xlabel("time [min]")
    axes[0].legend(fontsize=8, loc="lower right")
    axes[1].set_yticks([0, 1, 2, 3], ["ok", "warn", "limit", "inhibit"])
    axes[1].set_ylabel("protection level")
    axes[1].set_xlabel("time [min]")
    axes[1].legend(fontsize=8, loc="upper left")
    rows = list(csv.DictReader(open(out / "launch_metrics.csv")))
    width = 0.8 / len(tcus)
    for k, name in enumerate(tcus):
        r = [x for x in rows if x["tcu"] == name]
        axes[2].bar(np.array([int(x["launch"]) for x in r]) + (k - 0.5 * (len(tcus) - 1)) * width,
                    [float(x["slip_energy_kJ"]) for x in r], width, color=colours.get(name, None), label=name)
    axes[2].set_xlabel("launch")
    axes[2].set_ylabel("slip energy [kJ]")
    axes[2].legend(fontsize=8)
    fig.suptitle("Thermal protection, scenario 'protection' (3500 kg, 12 %, a hill start every 20 s)")
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


if __name__ == "__main__":      # python -m cushion_clutch.launch.tcu.protection <launch output folder> <png>
    import sys
    print(plot_protection(Path(sys.argv[1]), Path(sys.argv[2])))
