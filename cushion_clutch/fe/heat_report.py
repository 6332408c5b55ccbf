"""The docs' table of ``cushion-clutch heat-path`` numbers (a markdown include written by the command)."""
from __future__ import annotations


def _pm(result: dict, key: str, fmt: str) -> str:
    v = result[key]
    u = result.get("uncertainty", {}).get(key)
    if not u:
        return format(v, fmt)
    return f"{format(v, fmt)} ({format(u['low'], fmt)} to {format(u['high'], fmt)})"


def numbers_markdown(result: dict) -> str:
    """A markdown table: the FE set beside the paper's, the checks and the ODE's error."""
    p = result["paper"]
    tl = result["two_lags"]
    rows = [
        ("U, facing to cushion spring [W/K]", _pm(result, "U_W_per_K", ".3g"), f"{p['U_W_per_K']:g}"),
        ("H, cushion spring to ambient [W/K]", _pm(result, "H_W_per_K", ".3g"), f"{p['H_W_per_K']:g}"),
        ("C, cushion spring heat capacity [J/K]", _pm(result, "C_J_per_K", ".3g"), f"{p['C_J_per_K']:g}"),
        ("τ = C/(U+H) [s]", _pm(result, "tau_s", ".3g"), f"{p['tau_s']:.3g}"),
        ("steady gain U/(U+H)", _pm(result, "gain", ".3f"), f"{p['gain']:.3f}"),
    ]
    out = [f"<!-- written by `{result.get('command') or 'cushion-clutch heat-path'}` at commit "
           f"{result.get('commit')}; do not edit -->", "",
           "| quantity | FE set `fe_default` (uncertainty band) | paper |", "|---|---|---|"]
    out += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    out += ["", "| check | value | bar |", "|---|---|---|",
            f"| C / (paddle steel mass {result['steel_mass_kg'] * 1e3:.1f} g × c "
            f"{result['steel_specific_heat_J_per_kg_K']:g} J/(kg K)) | {result['C_over_mass_c']:.3f} | "
            f"C within 10 % of mass × c for c in {result['steel_specific_heat_range_J_per_kg_K'][0]:g}-"
            f"{result['steel_specific_heat_range_J_per_kg_K'][1]:g} J/(kg K) |",
            f"| energy balance error (heat in − stored − lost, / heat in) | {result['energy_balance_error']:.1e} | 0.01 |",
            f"| τ change between the two finest meshes ({result['meshes'][-2]['element_size_m'] * 1e3:g} and "
            f"{result['meshes'][-1]['element_size_m'] * 1e3:g} mm) | {result['tau_mesh_change']:.1%} | 5 % |",
            f"| first-order ODE − FE θ_cs: RMS / max (θ_cs rise {result['theta_cs_max_rise_K']:.2f} K) | "
            f"{result['ode_rms_error_K']:.3f} K / {result['ode_max_error_K']:.3f} K | - |",
            f"| two lags (gains {tl['gain_1']:.3f}, {tl['gain_2']:.3f}; τ {tl['tau_1_s']:.3g} s, {tl['tau_2_s']:.3g} s) − FE: "
            f"RMS / max | {tl['rms_error_K']:.3f} K / {tl['max_error_K']:.3f} K | - |",
            f"| U from the integrated heat flow instead (identification spread) | "
            f"{result['U_integrated_W_per_K']:.3g} W/K | - |"]
    ks = result.get("kiss_shift")
    if ks:
        names = {"uniform_kappa_spring": f"uniform paddle temperature, carrier at κ = {ks['kappa_spring']:g} of its rise "
                                         "(the sweep's case)",
                 "uniform_kappa_fe": f"uniform paddle temperature, carrier at the FE's κ = {ks['kappa_fe']:.3f}",
                 "field_kappa_fe": f"the FE's paddle field ({ks['field_min_over_mean']:.2f} to "
                                   f"{ks['field_max_over_mean']:.2f} of its mean rise), carrier at κ = {ks['kappa_fe']:.3f}"}
        held = f"{ks['far_end_stiffness_N_per_m'] / 1e6:.2f} MN/m"
        held += (" (predicted joint)" if ks.get("far_end_source", "").startswith("predicted") else " (given)")
        out += ["", f"| kiss shift at {ks['theta_degC']:g} °C (paddle mean), pair, structural mesh "
                    f"{ks['mesh_m'] * 1e3:g} mm, far edge held by {held} | Δ kiss | paper |", "|---|---|---|"]
        for key, label in names.items():
            v = ks["delta_kiss_m"].get(key)
            out.append(f"| {label} | {'failed: ' + ks['errors'].get(key, '') if v is None else f'{v * 1e3:.3f} mm'} | "
                       f"{ks['paper_delta_kiss_m'] * 1e3:g} mm |")
    return "\n".join(out) + "\n"
