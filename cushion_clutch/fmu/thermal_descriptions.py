"""modelDescription.xml (FMI 2.0 and 3.0) and buildDescription.xml of the thermal clutch FMU.

Written from the clutch FMU's own descriptions (:mod:`.descriptions`: units, log categories and
every clutch variable with its attributes, as they stand) and changed where the thermal variant
differs: model name and identifier, source files, ``theta_cm`` an output (the network's facing
mean, no start value), the variables of :func:`.thermal_chain.thermal_variables` after the
clutch's, then ``der(theta_cs)`` (value reference = position, as in the C table), ``time`` (FMI 3.0) last,
and the ModelStructure (outputs, the states theta_cs and the network's nodes in this order, and
their dependencies).
"""
from __future__ import annotations

import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..model import clutch_model
from .constants import sources
from .descriptions import (_finish, dependencies, float64_attributes, fmi2_description, fmi3_build_description,
                           fmi3_description, scalar_real, vr_der)
from .thermal_chain import (FRICTION_OUTPUT, NETWORK_SOURCES, THERMAL_SLAVE, Chain, node_output, thermal_ranges,
                            thermal_starts, thermal_variables)

DESCRIPTION = ("Dry-clutch torque (the CushionClutch model) with the clutch's thermal network inside: a chain of "
               "lumped nodes heated by the slip power torque*|omega_slip| and cooled by speed-dependent "
               "convection; theta_cm is the facing nodes' mean and drives the cushion-spring ODE "
               "(native C; Co-Simulation and Model Exchange)")
#: units the variant adds to the clutch FMU's
UNITS = {"W": {"kg": "1", "m": "2", "s": "-3"}, "m2": {"m": "2"}, "W/(m2.K)": {"kg": "1", "s": "-3", "K": "-1"}}


def thermal_sources(fmi_version: int) -> tuple[str, ...]:
    """C files compiled into the thermal FMU's binary."""
    return (*sources(fmi_version), *NETWORK_SOURCES)


def _all(chain: Chain) -> list[tuple[int, str, str, str, str]]:
    """(vr, name, causality, unit, description) of every variable but time, in value-reference order."""
    base, extra = thermal_variables(chain)
    out = [(vr, *v) for vr, v in enumerate((*base, *extra))]
    out.append((len(out), "der(theta_cs)", "local", "K/s", "rate of change of theta_cs (paper eq. 3)"))
    return out


def thermal_vr_der(chain: Chain) -> int:
    """Value reference of der(theta_cs) in the thermal FMU: the last (``CC_VR_DER_THETA_CS``)."""
    return len(_all(chain)) - 1


def thermal_dependencies(chain: Chain, has_friction: bool) -> tuple[dict[int, list[int]], list[int]]:
    """({output or derivative vr: vrs of the inputs and states it depends on}, derivative vrs in state order)."""
    vr = {v[1]: v[0] for v in _all(chain)}
    plain = dependencies(has_friction)
    facings = [vr[node_output(k)] for k, w in zip(chain.nodes, chain.theta_cm_weights) if w]
    nodes = [vr[node_output(k)] for k in chain.nodes]
    inputs = [vr["x_to"], vr["omega_slip"], vr["omega_engine"]]
    theta_cm = vr["theta_cm"]
    deps = {}
    for out, d in plain.items():          # the clutch's outputs: theta_cm stands for the facing nodes
        deps[thermal_vr_der(chain) if out == vr_der() else out] = sorted(
            {x for v in d for x in (facings if v == theta_cm else [v])})
    deps[theta_cm] = sorted(facings)
    surfaces = [vr[node_output(k)] for k, w in zip(chain.nodes, chain.theta_friction_weights) if w]
    if has_friction:                      # mu(theta_friction, omega_slip): the torque and validity see the surfaces
        for out in (vr["torque"], vr["validity"]):
            deps[out] = sorted(set(deps[out]) | set(surfaces))
    deps[vr["slip_power"]] = sorted(set(deps[vr["torque"]]) | {vr["omega_slip"]})
    for k in nodes:
        deps[k] = [k]
    deps[vr[FRICTION_OUTPUT]] = sorted(surfaces)
    ders = [thermal_vr_der(chain)] + [vr[f"der({node_output(k)})"] for k in chain.nodes]
    for d in ders[1:]:
        deps[d] = sorted({vr["theta_cs"], *nodes, *inputs})
    return deps, ders


def _bounds(chain: Chain, name: str) -> dict[str, str]:
    """FMI ``min``/``max`` of a variant's input, parameter or bounded output: its closed range bounds (an open bound
    is left out)."""
    rng = thermal_ranges(chain).get(name)
    if rng is None:
        return {}
    lo, hi, lo_open, hi_open = rng
    return {**({} if lo_open else {"min": repr(float(lo))}), **({} if hi_open else {"max": repr(float(hi))})}


def _outputs(chain: Chain) -> list[int]:
    return [v[0] for v in _all(chain) if v[2] == "output"]


def _add_units(root: ET.Element) -> None:
    units = root.find("UnitDefinitions")
    for name, base in UNITS.items():
        if units.find(f"Unit[@name='{name}']") is None:
            unit = ET.SubElement(units, "Unit", name=name)
            ET.SubElement(unit, "BaseUnit", base)


def _head(root: ET.Element, fmi_version: int) -> None:
    root.set("modelName", THERMAL_SLAVE)
    root.set("description", DESCRIPTION)
    for kind in ("ModelExchange", "CoSimulation"):
        element = root.find(kind)
        element.set("modelIdentifier", THERMAL_SLAVE)
        files = element.find("SourceFiles")
        if files is not None:
            element.remove(files)
            files = ET.SubElement(element, "SourceFiles")
            for name in thermal_sources(fmi_version):
                ET.SubElement(files, "File", name=name)
    _add_units(root)


def _theta_cm_description(chain: Chain) -> str:
    return next(d for _, n, _, u, d in _all(chain) if n == "theta_cm") + " [K]"


def thermal_fmi2_description(guid: str, has_friction: bool, chain: Chain, x_kiss_ref_m: float | None = None,
                             table=None) -> str:
    """FMI 2.0 modelDescription.xml of the thermal FMU (ME and CS; ``table``: its SpringTable)."""
    root = ET.fromstring(fmi2_description(guid, has_friction, x_kiss_ref_m, table))
    _head(root, 2)
    p = None if x_kiss_ref_m is None else clutch_model.ClutchParameters(x_kiss_ref=x_kiss_ref_m)
    starts = thermal_starts(chain, p)
    variables = root.find("ModelVariables")
    der_cs = None
    for sv in variables.findall("ScalarVariable"):
        if sv.get("name") == "theta_cm":
            sv.set("causality", "output")
            sv.set("description", _theta_cm_description(chain))
            real = sv.find("Real")
            real.attrib.pop("start", None)
        elif sv.get("name") == "der(theta_cs)":       # moves to the end: the last value reference
            der_cs = sv
            variables.remove(sv)
            sv.set("valueReference", str(thermal_vr_der(chain)))
    index = {}
    for vr, name, causality, unit, desc in _all(chain):
        index[name] = vr + 1
        if vr < len(clutch_model.VARIABLES) or name == "der(theta_cs)":
            continue
        real = scalar_real(variables, vr, name, causality, unit, desc)
        if causality in ("input", "parameter"):
            real.set("start", repr(starts[name]))
        for k, v in _bounds(chain, name).items():   # inputs, parameters and the nodes (thermal_ranges)
            real.set(k, v)
        if name.startswith("der("):
            real.set("derivative", str(index[name[4:-1]]))
    variables.append(der_cs)
    deps, ders = thermal_dependencies(chain, has_friction)
    root.remove(root.find("ModelStructure"))
    structure = ET.SubElement(root, "ModelStructure")
    idx = lambda vrs: " ".join(str(v + 1) for v in vrs)  # noqa: E731
    outputs = ET.SubElement(structure, "Outputs")
    for vr in _outputs(chain):
        ET.SubElement(outputs, "Unknown", index=str(vr + 1), dependencies=idx(deps[vr]))
    derivatives = ET.SubElement(structure, "Derivatives")
    for vr in ders:
        ET.SubElement(derivatives, "Unknown", index=str(vr + 1), dependencies=idx(deps[vr]))
    init = ET.SubElement(structure, "InitialUnknowns")
    for vr in sorted([*_outputs(chain), *ders]):
        ET.SubElement(init, "Unknown", index=str(vr + 1))
    return _finish(root)


def thermal_fmi3_description(token: str, has_friction: bool, chain: Chain, x_kiss_ref_m: float | None = None,
                             table=None) -> str:
    """FMI 3.0 modelDescription.xml of the thermal FMU (ME and CS, independent variable time; ``table``: its
    SpringTable)."""
    root = ET.fromstring(fmi3_description(token, has_friction, x_kiss_ref_m, table))
    _head(root, 3)
    p = None if x_kiss_ref_m is None else clutch_model.ClutchParameters(x_kiss_ref=x_kiss_ref_m)
    starts = thermal_starts(chain, p)
    all_ = _all(chain)
    variables = root.find("ModelVariables")
    der_cs = None
    for v in list(variables):
        if v.get("name") == "theta_cm":
            v.set("causality", "output")
            v.set("description", _theta_cm_description(chain))
            v.attrib.pop("start", None)
        elif v.get("name") == "time":
            v.set("valueReference", str(len(all_)))
        elif v.get("name") == "der(theta_cs)":        # moves to the end: the last value reference
            der_cs = v
            variables.remove(v)
            v.set("valueReference", str(thermal_vr_der(chain)))
    vrs = {name: vr for vr, name, *_ in all_}
    for vr, name, causality, unit, desc in all_:
        if vr < len(clutch_model.VARIABLES) or name == "der(theta_cs)":
            continue
        attrs = float64_attributes(vr, name, causality, unit, desc)
        if name.startswith("der("):
            attrs["derivative"] = str(vrs[name[4:-1]])
        if causality in ("input", "parameter"):
            attrs["start"] = repr(starts[name])
        attrs.update(_bounds(chain, name))          # inputs, parameters and the nodes (thermal_ranges)
        ET.SubElement(variables, "Float64", attrs)
    variables.append(der_cs)
    deps, ders = thermal_dependencies(chain, has_friction)
    root.remove(root.find("ModelStructure"))
    structure = ET.SubElement(root, "ModelStructure")
    for vr in _outputs(chain):
        ET.SubElement(structure, "Output", valueReference=str(vr), dependencies=" ".join(map(str, deps[vr])))
    for vr in ders:
        ET.SubElement(structure, "ContinuousStateDerivative", valueReference=str(vr),
                      dependencies=" ".join(map(str, deps[vr])))
    for vr in sorted([*_outputs(chain), *ders]):
        ET.SubElement(structure, "InitialUnknown", valueReference=str(vr))
    return _finish(root)


def thermal_fmi3_build_description() -> str:
    """sources/buildDescription.xml of the FMI 3.0 thermal FMU."""
    return fmi3_build_description(THERMAL_SLAVE, thermal_sources(3))


def thermal_descriptions_into(fmu: Path, guid: str, has_friction: bool, chain: Chain, x_kiss_ref_m: float | None,
                              fmi_version: int, table=None) -> None:
    """Replace ``modelDescription.xml`` (and, FMI 3.0, ``sources/buildDescription.xml``) in the built ``fmu``
    with the thermal variant's (the native build writes the clutch FMU's; binaries and sources are the variant's)."""
    fmu = Path(fmu)
    replace = {"modelDescription.xml": thermal_fmi2_description(guid, has_friction, chain, x_kiss_ref_m, table)
               if fmi_version == 2 else thermal_fmi3_description(guid, has_friction, chain, x_kiss_ref_m, table)}
    if fmi_version == 3:
        replace["sources/buildDescription.xml"] = thermal_fmi3_build_description()
    tmp = fmu.with_suffix(".fmu.tmp")
    try:
        with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
            for info in src.infolist():
                dst.writestr(info.filename, replace.get(info.filename) or src.read(info.filename))
        tmp.replace(fmu)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
