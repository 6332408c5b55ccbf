"""Benchmark: cost of one call of the Python clutch model's hot paths, on the default tables and parameters.

    python -m cushion_clutch.benchmarks.model_speed [--n 20000] [--repeat 5]

- ``step``: the FMU benchmark's "Python model alone" loop (``thermal_step`` + ``outputs``, the temperature
  changing every step, so every call prepares a new cover frame);
- ``outputs``: ``outputs`` at one temperature pair over a sweep of ``x_to`` (the frame cached);
- ``state``: the cover's forward map ``_Frame.state`` alone over the whole stroke (frame cached; a bearing
  position past the solid point needs no Newton iteration);
- ``state_cushion``: the same between the kiss and the solid points, where the TCUs work;
- ``x_for_clamp``: the inverse (``_Frame.x_for_clamp``) over a sweep of clamp forces (frame cached);
- ``x_to_for_torque``: the API inverse at a temperature that changes every call (a new frame each call);
- ``prepare``: building a frame (``CoverMap.prepare``) at a new temperature.

Each figure is the median of ``--repeat`` runs, in us of CPU time (``time.process_time``) per call. Per-call times on a shared machine are noisy:
compare figures from one run.
"""
from __future__ import annotations

import argparse
import statistics
import time


def _time(fn, n: int, repeat: int) -> float:
    runs = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn(n)
        runs.append((time.process_time() - t0) / n * 1e6)
    return statistics.median(runs)


def measure(n: int = 20000, repeat: int = 5) -> dict[str, float]:
    """us per call of each hot path (median of ``repeat`` runs of ``n`` calls)."""
    from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step, x_to_for_torque
    from cushion_clutch.model.clutch_model import _cover_map, cover_frame

    table, p = load_table(), ClutchParameters()
    g = _cover_map(p.cover, p.lever_ratio)
    fr = cover_frame(table, p, 400.0, 420.0)
    xs = [-0.001 + 0.022 * k / 997.0 for k in range(997)]
    xc = [fr.x_kiss + (fr.x_solid - fr.x_kiss) * (k + 0.5) / 997.0 for k in range(997)]
    fs = [8000.0 * k / 991.0 for k in range(991)]

    def step(m):
        theta = 293.15
        for k in range(m):
            theta = thermal_step(theta, 450.0, 1e-3, p)
            outputs(0.003 + 0.004 * (k % 1000) / 1000.0, theta, table, p)

    def outs(m):
        for k in range(m):
            outputs(xs[k % 997], 400.0, table, p, 420.0)

    def state(m):
        fr_state = fr.state
        for k in range(m):
            fr_state(xs[k % 997])

    def state_cushion(m):
        fr_state = fr.state
        for k in range(m):
            fr_state(xc[k % 997])

    def inverse(m):
        inv = fr.x_for_clamp
        for k in range(m):
            inv(fs[k % 991])

    def api_inverse(m):
        for k in range(m):
            x_to_for_torque(10.0 + 200.0 * (k % 991) / 991.0, 300.0 + 0.37 * (k % 1009), table, p)

    def prepare(m):
        for k in range(m):
            g.prepare(300.0 + 1e-3 * k, 320.0, 0.0, table, p.x_kiss_ref)

    return {"step": _time(step, n, repeat), "outputs": _time(outs, n, repeat), "state": _time(state, n, repeat),
            "state_cushion": _time(state_cushion, n, repeat),
            "x_for_clamp": _time(inverse, n, repeat), "x_to_for_torque": _time(api_inverse, n, repeat),
            "prepare": _time(prepare, n, repeat)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    for k, v in measure(a.n, a.repeat).items():
        print(f"{k:>16}: {v:8.3f} us/call")


if __name__ == "__main__":
    main()
