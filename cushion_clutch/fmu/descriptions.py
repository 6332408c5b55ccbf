"""modelDescription.xml (FMI 2.0 and 3.0) and buildDescription.xml of the native FMU.

Both FMI versions carry Co-Simulation and Model Exchange. The variables are
``clutch_model.VARIABLES`` (value reference = position; start values from
``clutch_model.start_values``) plus the state derivative ``der(theta_cs)`` [K/s]
(value reference ``len(VARIABLES)``, today 18) and, in FMI 3.0, the independent
variable ``time`` [s] (the next one, today 19). In Model Exchange ``theta_cs`` is
the continuous state; torque, force, u_f and x_kiss depend directly on the inputs
(ModelStructure lists the dependencies). The model is read when a description
is written, so the descriptions follow ``VARIABLES`` as it stands.

Hosts show kelvin variables in degC and lengths (unit ``m``: ``x_to``, ``x_kiss``, ``u_f``, ``facing_wear``, the
cover's dimensions, ...) in mm (:data:`DISPLAY_UNITS`, FMI ``DisplayUnit``; the FMU's values stay SI).
Every input and parameter carries ``min``, ``max`` and ``nominal`` from the model's one validity table
(:func:`bounds_attributes`, from ``clutch_model.variable_bounds``); the pythonfmu backend writes the same
attributes into its description with the same function.
"""
from __future__ import annotations

from xml.etree import ElementTree as ET

from ..model import clutch_model
from .constants import BASE_UNITS, SLAVE, sources

UNITS = dict(BASE_UNITS, **{"K/s": {"K": "1", "s": "-1"}, "s": {"s": "1"}})
DESCRIPTION = ("Dry-clutch torque T = n*mu*R_eq*F(u_f(x_to, theta_cs), theta_cs) with the cushion-spring "
               "thermal ODE C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs); F from "
               "CalculiX tables (native C; Co-Simulation and Model Exchange)")


#: the display unit of a variable's unit, with its FMI DisplayUnit attributes (display = factor * value + offset)
DISPLAY_UNITS = {"K": ("degC", {"offset": "-273.15"}), "m": ("mm", {"factor": "1000"})}


def display_unit(unit: str) -> str | None:
    """The display unit hosts show for ``unit`` (degC for K, mm for m), None if it is shown as it is."""
    return DISPLAY_UNITS[unit][0] if unit in DISPLAY_UNITS else None


def add_display_unit(unit_element: ET.Element, unit: str) -> None:
    """Append ``unit``'s ``DisplayUnit`` (if it has one) to its ``<Unit>`` element in ``UnitDefinitions``."""
    if unit in DISPLAY_UNITS:
        name, attrs = DISPLAY_UNITS[unit]
        ET.SubElement(unit_element, "DisplayUnit", dict(name=name, **attrs))


def vr_der() -> int:
    """Value reference of der(theta_cs): the first after the model's variables."""
    return len(clutch_model.VARIABLES)


def vr_time() -> int:
    """Value reference of the independent variable time (FMI 3.0)."""
    return vr_der() + 1


def _vr(name: str) -> int:
    return [v[0] for v in clutch_model.VARIABLES].index(name)


def dependencies(has_friction: bool) -> dict[int, list[int]]:
    """Value references of the inputs and states each output and the derivative depend on."""
    x_to, theta_cm, theta_cs, omega = _vr("x_to"), _vr("theta_cm"), _vr("theta_cs"), _vr("omega_slip")
    # the cover's stack grows with theta_cm: every force and the kiss point depend on it
    cover = [x_to, theta_cm, theta_cs]
    torque = cover + ([omega] if has_friction else [])
    return {_vr("torque"): sorted(torque), _vr("force"): cover, theta_cs: [theta_cs], _vr("u_f"): cover,
            _vr("x_kiss"): [theta_cm, theta_cs], _vr("clamp_force"): cover, _vr("bearing_force"): cover,
            _vr("validity"): [theta_cm, theta_cs],
            vr_der(): [theta_cm, theta_cs]}


def _variables(x_kiss_ref_m: float | None = None):
    """(vr, name, causality, unit, description, start) of every variable but time (start: inputs and parameters).

    ``x_kiss_ref_m``: the table set's own start value of ``x_kiss_ref`` (m), None for the default.
    """
    p = None if x_kiss_ref_m is None else clutch_model.ClutchParameters(x_kiss_ref=x_kiss_ref_m)
    starts = clutch_model.start_values(p)
    for vr, (name, causality, unit, desc) in enumerate(clutch_model.VARIABLES):
        yield vr, name, causality, unit, desc, starts[name] if causality in ("input", "parameter") else None
    yield vr_der(), "der(theta_cs)", "local", "K/s", "rate of change of theta_cs (paper eq. 3)", None


def bounds_attributes(name: str, bounds: dict | None = None) -> dict[str, str]:
    """``min``, ``max`` and ``nominal`` (XML attribute text) of an input, parameter or bounded output; {} for other
    variables. ``bounds``: :func:`clutch_model.variable_bounds` of the FMU's table set (default: without a table,
    ``facing_wear`` then has its absolute range)."""
    b = (clutch_model.variable_bounds() if bounds is None else bounds).get(name)
    return {} if b is None else {"min": repr(b[0]), "max": repr(b[1]), "nominal": repr(b[2])}


def _wear_note(desc: str, name: str, bounds: dict) -> str:
    """A variable's description, for ``facing_wear`` with where its declared maximum comes from."""
    if name != "facing_wear":
        return desc
    return (f"{desc}; max {bounds[name][1]!r} m is the default cover's wear limit with this FMU's tables "
            "(initialisation refuses more; another cover is checked at initialisation)")


def _units(root: ET.Element) -> None:
    units = ET.SubElement(root, "UnitDefinitions")
    for name, base in UNITS.items():
        unit = ET.SubElement(units, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", base)
        add_display_unit(unit, name)


def _log_categories(root: ET.Element) -> None:
    cats = ET.SubElement(root, "LogCategories")
    for name in ("logStatusWarning", "logStatusDiscard", "logStatusError", "logAll"):
        ET.SubElement(cats, "Category", name=name)


def _finish(root: ET.Element) -> str:
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"



def _common_attributes(vr: int, name: str, causality: str, unit: str, desc: str) -> dict[str, str]:
    """A variable's attributes common to FMI 2.0 and 3.0: parameters fixed and exact, everything else
    continuous; the description ends with the unit."""
    attrs = dict(name=name, valueReference=str(vr), description=f"{desc} [{unit}]", causality=causality)
    attrs.update(variability="fixed", initial="exact") if causality == "parameter" else attrs.update(
        variability="continuous")
    return attrs


def scalar_real(variables: ET.Element, vr: int, name: str, causality: str, unit: str, desc: str) -> ET.Element:
    """Append an FMI 2.0 ``ScalarVariable`` with its ``Real`` element to ``variables``; return the ``Real``
    (with its display unit: degC for K, mm for m)."""
    real = ET.SubElement(ET.SubElement(variables, "ScalarVariable", _common_attributes(vr, name, causality, unit,
                                                                                        desc)), "Real", unit=unit)
    if display_unit(unit):
        real.set("displayUnit", display_unit(unit))
    return real


def float64_attributes(vr: int, name: str, causality: str, unit: str, desc: str) -> dict[str, str]:
    """The attributes of an FMI 3.0 ``Float64`` variable (with its unit and display unit: degC for K, mm for m)."""
    attrs = _common_attributes(vr, name, causality, unit, desc)
    attrs["unit"] = unit
    if display_unit(unit):
        attrs["displayUnit"] = display_unit(unit)
    return attrs

def fmi2_description(guid: str, has_friction: bool, x_kiss_ref_m: float | None = None, table=None) -> str:
    """FMI 2.0 modelDescription.xml: ME and CS, SourceFiles, ModelStructure with dependencies."""
    root = ET.Element("fmiModelDescription", fmiVersion="2.0", modelName=SLAVE, guid=guid, description=DESCRIPTION,
                      generationTool="cushion_clutch (native C)", variableNamingConvention="flat",
                      numberOfEventIndicators="0")
    common = dict(modelIdentifier=SLAVE, needsExecutionTool="false", canBeInstantiatedOnlyOncePerProcess="false",
                  canNotUseMemoryManagementFunctions="true", canGetAndSetFMUstate="true",
                  canSerializeFMUstate="true")
    me = ET.SubElement(root, "ModelExchange", common, completedIntegratorStepNotNeeded="true")
    cs = ET.SubElement(root, "CoSimulation", common, canHandleVariableCommunicationStepSize="true",
                       canInterpolateInputs="false")
    for element in (me, cs):
        files = ET.SubElement(element, "SourceFiles")
        for name in sources(2):
            ET.SubElement(files, "File", name=name)
    _units(root)
    _log_categories(root)
    variables = ET.SubElement(root, "ModelVariables")
    bounds = clutch_model.variable_bounds(table)   # table: the FMU's SpringTable (facing_wear's declared max)
    for vr, name, causality, unit, desc, start in _variables(x_kiss_ref_m):
        real = scalar_real(variables, vr, name, causality, unit, _wear_note(desc, name, bounds))
        if vr == vr_der():
            real.set("derivative", str(_vr("theta_cs") + 1))
        for key, value in bounds_attributes(name, bounds).items():
            real.set(key, value)
        if start is not None:
            real.set("start", repr(start))
    deps = dependencies(has_friction)
    index = lambda vrs: " ".join(str(v + 1) for v in vrs)  # noqa: E731
    structure = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(structure, "Outputs")
    for vr, (_, causality, _, _) in enumerate(clutch_model.VARIABLES):
        if causality == "output":
            ET.SubElement(outputs, "Unknown", index=str(vr + 1), dependencies=index(deps[vr]))
    ET.SubElement(ET.SubElement(structure, "Derivatives"), "Unknown", index=str(vr_der() + 1),
                  dependencies=index(deps[vr_der()]))
    init = ET.SubElement(structure, "InitialUnknowns")
    for vr in sorted(deps):
        ET.SubElement(init, "Unknown", index=str(vr + 1))
    return _finish(root)


def fmi3_description(token: str, has_friction: bool, x_kiss_ref_m: float | None = None, table=None) -> str:
    """FMI 3.0 modelDescription.xml: ME and CS, independent variable time, ModelStructure."""
    root = ET.Element("fmiModelDescription", fmiVersion="3.0", modelName=SLAVE, instantiationToken=token,
                      description=DESCRIPTION, generationTool="cushion_clutch (native C)",
                      variableNamingConvention="flat")
    common = dict(modelIdentifier=SLAVE, canGetAndSetFMUState="true", canSerializeFMUState="true")
    ET.SubElement(root, "ModelExchange", common, needsCompletedIntegratorStep="false")
    ET.SubElement(root, "CoSimulation", common, canHandleVariableCommunicationStepSize="true",
                  hasEventMode="false")
    _units(root)
    _log_categories(root)
    variables = ET.SubElement(root, "ModelVariables")
    ET.SubElement(variables, "Float64", name="time", valueReference=str(vr_time()), causality="independent",
                  variability="continuous", unit="s", description="simulation time [s]")
    bounds = clutch_model.variable_bounds(table)   # table: the FMU's SpringTable (facing_wear's declared max)
    for vr, name, causality, unit, desc, start in _variables(x_kiss_ref_m):
        attrs = float64_attributes(vr, name, causality, unit, _wear_note(desc, name, bounds))
        if vr == vr_der():
            attrs["derivative"] = str(_vr("theta_cs"))
        attrs.update(bounds_attributes(name, bounds))
        if start is not None:
            attrs["start"] = repr(start)
        ET.SubElement(variables, "Float64", attrs)
    deps = dependencies(has_friction)
    structure = ET.SubElement(root, "ModelStructure")
    for vr, (_, causality, _, _) in enumerate(clutch_model.VARIABLES):
        if causality == "output":
            ET.SubElement(structure, "Output", valueReference=str(vr), dependencies=" ".join(map(str, deps[vr])))
    ET.SubElement(structure, "ContinuousStateDerivative", valueReference=str(vr_der()),
                  dependencies=" ".join(map(str, deps[vr_der()])))
    for vr in sorted(deps):
        ET.SubElement(structure, "InitialUnknown", valueReference=str(vr))
    return _finish(root)


def fmi3_build_description(model_identifier: str = SLAVE, source_files: list[str] | None = None) -> str:
    """sources/buildDescription.xml of an FMI 3.0 FMU (default: the clutch FMU and its sources)."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    config = ET.SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier)
    files = ET.SubElement(config, "SourceFileSet", language="C99")
    for name in sources(3) if source_files is None else source_files:
        ET.SubElement(files, "SourceFile", name=name)
    return _finish(root)
