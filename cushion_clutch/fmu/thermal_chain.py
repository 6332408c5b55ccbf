"""The thermal clutch FMU (``CushionClutchThermal``): the plant's thermal network as a generated C chain.

The clutch model is the native FMU's, unchanged (``clutch_core.c`` and friends); the thermal
variant compiles it with ``thermal_network.c`` (a chain of N lumped nodes that knows no node by
name), ``clutch_thermal.c`` (the network inside the model: parameters, CS step, ME states) and a
second generated variable table. Everything the C chain needs comes from here:

* :class:`Chain`: the network as arrays (nodes, capacities, heat shares, cooled areas with their
  speed source, engine-block conductances, link conductances (always, and added while clamped),
  the weights of the facing temperature ``theta_cm``). :func:`chain_of` maps the plant's
  :class:`~cushion_clutch.model.thermal_network.NetworkParams` onto it; a new node list is a
  new :class:`Chain`, and the C table, the FMU variables and the descriptions follow.
* :func:`thermal_variables`: the FMU interface. ``clutch_model.VARIABLES`` in their order with
  ``theta_cm`` turned into an output (the network's facing mean), then the input ``omega_engine``,
  the output ``slip_power``, the node temperatures (outputs, the network's states), the network's
  parameters and the node derivatives; ``der(theta_cs)`` last.
* :func:`thermal_header`: ``cushion_variables.h`` of the variant (:func:`.variable_table.variable_header`
  with the extra variables and a block of value-reference arrays for the chain).

Per Co-Simulation step (inputs held), the order of the launch plant
(:mod:`cushion_clutch.launch.simulate`): theta_cs advances with theta_cm held; the torque at the new
theta_cs and the old theta_cm gives the slip power ``P = torque |omega_slip|`` and the clamp state
(clamp force > 0); the network advances with ``ThermalNetwork.step``'s exact-exponential
Gauss-Seidel splitting at the engine speed ``omega_engine`` and the disc speed
``omega_engine - omega_slip``; theta_cm becomes the new facing mean and the outputs are those at
the step's end. Model Exchange: theta_cs and the nodes are the continuous states.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..model import clutch_model
from .variable_table import enum_name, variable_header

#: model identifier and modelName of the thermal variant
THERMAL_SLAVE = "CushionClutchThermal"
#: C sources of the network (compiled with the clutch core)
NETWORK_SOURCES = ("thermal_network.c", "thermal_step.c", "clutch_thermal.c")
NETWORK_HEADERS = ("thermal_network.h", "thermal_step.h")
#: start value of the engine-speed input, rad/s (0: still-air convection on flywheel and pressure plate)
OMEGA_ENGINE_START = 0.0
#: speed sources of the convection (thermal_network.h TN_ENGINE, TN_DISC)
SPEEDS = {"engine": "TN_ENGINE", "disc": "TN_DISC"}
#: the most nodes the C chain holds (thermal_network.h TN_MAX)
TN_MAX = 32
#: the output of the friction-surface temperature (K), at which mu of a friction table is read
FRICTION_OUTPUT = "theta_friction"

#: highest temperature of any network node, K: 1000 degC. No part of a dry clutch survives it (grey iron melts near
#: 1150 degC, organic facings char by about 530 degC); a step or a state beyond it is refused
NODE_MAX_K = 1273.15
#: the one range of every node temperature ``theta_<node>`` (low, high, low open, high open): the modelDescription's
#: min/max, the C checks of the CS step, the ME states and restored states (TN_THETA_MIN_K, TN_THETA_MAX_K), the docs.
#: The low end is the model's: no sink is colder (theta_a, theta_engine) and every node starts at theta_network_start
NODE_RANGE = (clutch_model.THETA_MIN_K, NODE_MAX_K, False, False)


@dataclass(frozen=True)
class Chain:
    """A chain of lumped thermal nodes (SI), node ``i`` linked to ``i + 1``.

    Link i conducts ``link_always_W_per_K[i]``, plus ``link_clamped_W_per_K[i]`` while the clutch is
    clamped. Sink of node i: convection ``cooled_area_m2[i] (h_still + h_rot (|w| / w_ref)^0.8)`` to the air,
    ``w`` the speed of ``speed[i]`` ("engine" or "disc"), plus ``engine_W_per_K[i]`` to the engine block at
    ``engine_K``. Slip power P puts ``heat_share[i] P`` into node i.
    ``theta_cm`` = sum of ``theta_cm_weights[i] theta_i``; the friction-surface temperature
    ``theta_friction`` (mu is read there) = sum of ``friction_weights[i] theta_i``.
    """

    nodes: tuple[str, ...]
    capacity_J_per_K: tuple[float, ...]
    heat_share: tuple[float, ...]
    cooled_area_m2: tuple[float, ...]
    speed: tuple[str, ...]
    engine_W_per_K: tuple[float, ...]
    link_always_W_per_K: tuple[float, ...]
    link_clamped_W_per_K: tuple[float, ...]
    theta_cm_weights: tuple[float, ...]
    engine_K: float
    still_air_W_per_m2_K: float
    rotating_W_per_m2_K: float
    convection_reference_rad_s: float
    friction_weights: tuple[float, ...] = ()
    """weights of ``theta_friction``; empty: those of ``theta_cm``"""

    def __post_init__(self) -> None:
        n = len(self.nodes)
        problems = [f"{k}: {len(getattr(self, k))} entries for {n} nodes" for k in
                    ("capacity_J_per_K", "heat_share", "cooled_area_m2", "speed", "engine_W_per_K",
                     "theta_cm_weights") if len(getattr(self, k)) != n]
        problems += [f"{k}: {len(getattr(self, k))} entries for {n - 1} links" for k in
                     ("link_always_W_per_K", "link_clamped_W_per_K") if len(getattr(self, k)) != n - 1]
        problems += [f"speed {s!r} (allowed {', '.join(SPEEDS)})" for s in self.speed if s not in SPEEDS]
        if not 1 <= n <= TN_MAX:
            problems.append(f"{n} nodes (allowed 1 to {TN_MAX})")
        if abs(sum(self.heat_share) - 1.0) > 1e-9:
            problems.append(f"heat shares add up to {sum(self.heat_share)!r}, not 1")
        if abs(sum(self.theta_cm_weights) - 1.0) > 1e-12:
            problems.append(f"theta_cm weights add up to {sum(self.theta_cm_weights)!r}, not 1")
        if self.friction_weights and (len(self.friction_weights) != n or abs(sum(self.friction_weights) - 1.0) > 1e-12):
            problems.append(f"friction weights: {len(self.friction_weights)} entries for {n} nodes adding up to "
                            f"{sum(self.friction_weights)!r} (need one per node, adding up to 1)")
        if problems:
            raise ValueError("thermal chain: " + "; ".join(problems))

    @property
    def theta_friction_weights(self) -> tuple[float, ...]:
        """Weights of the friction-surface temperature ``theta_friction``, one per node."""
        return self.friction_weights or self.theta_cm_weights

    def links(self) -> list[tuple[str, str]]:
        """(node i, node i + 1) of every link."""
        return list(zip(self.nodes[:-1], self.nodes[1:]))


def chain_of(p=None) -> Chain:
    """The plant's network (:class:`~cushion_clutch.model.thermal_network.NetworkParams`, default: its
    defaults) as a :class:`Chain`, in the plant's node order and with its conductance laws, taken as they are
    from the network's arrays (``thermal_network.coefficients``).
    """
    from ..model import thermal_network as tn
    from ..model import KELVIN
    p = p or tn.NetworkParams()
    c = tn.coefficients(p)
    n = len(tn.NODES)
    return Chain(nodes=tuple(tn.NODES), capacity_J_per_K=tuple(c["caps"]), heat_share=tuple(c["shares"]),
                 cooled_area_m2=tuple(c["area_cooled"]),
                 speed=tuple(("engine", "disc")[s] for s in tn.SPEED_OF_NODE),
                 engine_W_per_K=tuple(c["engine"]), link_always_W_per_K=tuple(c["link_always"]),
                 link_clamped_W_per_K=tuple(c["link_clamped"]),
                 theta_cm_weights=tuple(0.5 if i in tn.FACINGS else 0.0 for i in range(n)),
                 friction_weights=tuple(0.5 if i in tn.SURFACES else 0.0 for i in range(n)),
                 engine_K=p.engine_degC + KELVIN, still_air_W_per_m2_K=p.still_air_W_per_m2_K,
                 rotating_W_per_m2_K=p.rotating_W_per_m2_K,
                 convection_reference_rad_s=p.convection_reference_rad_s)


# ---------------------------------------------------------------- variable names
def node_output(node: str) -> str:
    """FMU name of a node's temperature (K)."""
    return f"theta_{node}"


def _node_params(node: str) -> dict[str, str]:
    return {"cap": f"C_{node}", "share": f"heat_share_{node}", "area": f"A_cooled_{node}",
            "engine": f"G_engine_{node}"}


def _link_params(a: str, b: str) -> dict[str, str]:
    return {"always": f"G_{a}__{b}", "clamped": f"G_{a}__{b}_clamped"}


#: range of every node's heat capacity C_<node>, J/K: at least 1 J/K (about 2 g of steel; the default's smallest node,
#: a 1 mm surface layer, holds 122 J/K), so that min > 0 is declared and the ME derivative stays finite
CAPACITY_RANGE = (1.0, 1e6, False, False)

#: the network's global parameters: name -> (unit, description, range)
GLOBALS = {
    "theta_engine": ("K", "engine block temperature (the sink of G_engine_*)", (223.15, 423.15, False, False)),
    "h_still_air": ("W/(m2.K)", "heat-transfer coefficient to the air at rest (convection and radiation)",
                    (0.0, 1e4, False, False)),
    "h_rotating": ("W/(m2.K)", "added heat-transfer coefficient of a part turning at convection_reference_omega",
                   (0.0, 1e4, False, False)),
    "convection_reference_omega": ("rad/s", "speed w_ref of the convection law A (h_still_air + h_rotating "
                                            "(|w| / w_ref)^0.8)", (1.0, 2000.0, False, False)),
    "theta_network_start": ("K", "initial temperature of every network node (the facings' mean is theta_cm: the "
                                 "range of theta_cm)", clutch_model.INPUT_RANGES["theta_cm"]),
}


def thermal_variables(chain: Chain) -> tuple[tuple, tuple]:
    """(base, extra): ``clutch_model.VARIABLES`` with theta_cm an output, and the variant's own variables.

    Value references: base, then extra, then ``der(theta_cs)`` (the last, ``CC_VR_DER_THETA_CS``).
    """
    base = tuple((n, "output", u, "clutch facing temperature: the network's facing mean "
                  + " + ".join(f"{w:g} {node_output(k)}" for k, w in zip(chain.nodes, chain.theta_cm_weights) if w))
                 if n == "theta_cm" else (n, c, u, d) for n, c, u, d in clutch_model.VARIABLES)
    extra = [("omega_engine", "input", "rad/s", "engine speed (flywheel, pressure plate); the disc turns at "
                                                "omega_engine - omega_slip; sets the convection"),
             ("slip_power", "output", "W", "slip heat flow into the network, torque * |omega_slip|")]
    extra += [(node_output(k), "output", "K", f"temperature of the network node {k} (a state)") for k in chain.nodes]
    for k, s in zip(chain.nodes, chain.speed):
        q = _node_params(k)
        extra += [(q["cap"], "parameter", "J/K", f"heat capacity of {k}"),
                  (q["share"], "parameter", "1", f"share of the slip power into {k}"),
                  (q["area"], "parameter", "m2", f"area of {k} cooled by the air (turns with the {s})"),
                  (q["engine"], "parameter", "W/K", f"conduction of {k} to the engine block at theta_engine")]
    for a, b in chain.links():
        q = _link_params(a, b)
        extra += [(q["always"], "parameter", "W/K", f"conductance {a} -- {b}"),
                  (q["clamped"], "parameter", "W/K", f"added conductance {a} -- {b} while the clutch is clamped "
                                                     "(clamp force > 0)")]
    extra += [(n, "parameter", u, d) for n, (u, d, _) in GLOBALS.items()]
    extra += [(f"der({node_output(k)})", "local", "K/s", f"rate of change of {node_output(k)}") for k in chain.nodes]
    extra.append((FRICTION_OUTPUT, "output", "K", "friction-surface temperature "
                  + " + ".join(f"{w:g} {node_output(k)}" for k, w in zip(chain.nodes, chain.theta_friction_weights)
                               if w) + "; mu(theta, omega_slip) of a friction table is read here (issue 37)"))
    return base, tuple(extra)


def thermal_starts(chain: Chain, p: "clutch_model.ClutchParameters | None" = None) -> dict[str, float]:
    """Start value of every variable of :func:`thermal_variables` (parameters: the chain's values)."""
    p = p or clutch_model.ClutchParameters()
    starts = clutch_model.start_values(p)
    theta0 = p.theta_cs_start
    starts["theta_cm"] = sum(w * theta0 for w in chain.theta_cm_weights)
    starts.update({"omega_engine": OMEGA_ENGINE_START, "slip_power": 0.0,
                   FRICTION_OUTPUT: sum(w * theta0 for w in chain.theta_friction_weights)})
    for i, k in enumerate(chain.nodes):
        q = _node_params(k)
        starts.update({node_output(k): theta0, f"der({node_output(k)})": 0.0, q["cap"]: chain.capacity_J_per_K[i],
                       q["share"]: chain.heat_share[i], q["area"]: chain.cooled_area_m2[i],
                       q["engine"]: chain.engine_W_per_K[i]})
    for i, (a, b) in enumerate(chain.links()):
        q = _link_params(a, b)
        starts.update({q["always"]: chain.link_always_W_per_K[i], q["clamped"]: chain.link_clamped_W_per_K[i]})
    starts.update({"theta_engine": chain.engine_K, "h_still_air": chain.still_air_W_per_m2_K,
                   "h_rotating": chain.rotating_W_per_m2_K, "convection_reference_omega":
                   chain.convection_reference_rad_s, "theta_network_start": theta0})
    return {k: float(v) for k, v in starts.items()}


def thermal_ranges(chain: Chain) -> dict[str, tuple]:
    """Allowed range (low, high, low open, high open) of every parameter of the variant, its input ``omega_engine``
    and its bounded outputs (``theta_cm``: the facing nodes' mean, in the clutch's theta_cm range; ``theta_cs``;
    every node: :data:`NODE_RANGE`)."""
    ranges = dict(clutch_model.ClutchParameters.RANGES)
    ranges.update(clutch_model.OUTPUT_RANGES)
    ranges["theta_cm"] = clutch_model.INPUT_RANGES["theta_cm"]
    for k in chain.nodes:
        q = _node_params(k)
        ranges[node_output(k)] = NODE_RANGE
        ranges.update({q["cap"]: CAPACITY_RANGE, q["share"]: (0.0, 1.0, False, False),
                       q["area"]: (0.0, 10.0, False, False), q["engine"]: (0.0, 1e4, False, False)})
    for a, b in chain.links():
        ranges.update({v: (0.0, 1e6, False, False) for v in _link_params(a, b).values()})
    ranges.update({n: r for n, (_, _, r) in GLOBALS.items()})
    ranges["omega_engine"] = (-clutch_model.OMEGA_SLIP_LIMIT, clutch_model.OMEGA_SLIP_LIMIT, False, False)
    ranges[FRICTION_OUTPUT] = NODE_RANGE         # the two metal surface nodes' mean: in their range when they are
    return ranges


def _c_array(ctype: str, name: str, values: list) -> str:
    return f"static const {ctype} {name}[] = {{{', '.join(str(v) for v in values)}}};"


def _block(chain: Chain) -> str:
    """The C block of the variant: chain size, state count, value-reference arrays, structure."""
    n = len(chain.nodes)
    nodes = [_node_params(k) for k in chain.nodes]
    links = [_link_params(a, b) for a, b in chain.links()] or [{"always": None, "clamped": None}]
    vr = lambda name: enum_name(name) if name else "-1"  # noqa: E731
    arrays = [
        _c_array("int", "TN_VR_THETA", [vr(node_output(k)) for k in chain.nodes]),
        _c_array("int", "TN_VR_DER", [vr(f"der({node_output(k)})") for k in chain.nodes]),
        _c_array("int", "TN_VR_CAP", [vr(q["cap"]) for q in nodes]),
        _c_array("int", "TN_VR_SHARE", [vr(q["share"]) for q in nodes]),
        _c_array("int", "TN_VR_AREA", [vr(q["area"]) for q in nodes]),
        _c_array("int", "TN_VR_ENGINE", [vr(q["engine"]) for q in nodes]),
        _c_array("int", "TN_VR_ALWAYS", [vr(q["always"]) for q in links]),
        _c_array("int", "TN_VR_CLAMPED", [vr(q["clamped"]) for q in links]),
        _c_array("int", "TN_SPEED", [SPEEDS[s] for s in chain.speed]),
        _c_array("double", "TN_WEIGHT", [repr(float(w)) for w in chain.theta_cm_weights]),
        _c_array("double", "TN_FRICTION_WEIGHT", [repr(float(w)) for w in chain.theta_friction_weights]),
        _c_array("char *const", "TN_NAME", [f'"{node_output(k)}"' for k in chain.nodes]),
    ]
    names = ", ".join(f'"{k}"' for k in chain.nodes)
    return f"""
/* the thermal variant (CushionClutchThermal): a chain of {n} nodes, generated by
   cushion_clutch.fmu.thermal_chain; nodes {names} */
#define CC_THERMAL 1
#define CC_HOOKS_TABLE cc_thermal_hooks /* the variant's hook table (clutch_core.h CcHooks; clutch_thermal.c) */
#include "thermal_network.h"
#define TN_N {n}
#define CC_NSTATES (1 + TN_N)
#define TN_VR_THETA_ENGINE {enum_name("theta_engine")}
#define TN_VR_H_STILL {enum_name("h_still_air")}
#define TN_VR_H_ROT {enum_name("h_rotating")}
#define TN_VR_WREF {enum_name("convection_reference_omega")}
#define TN_VR_THETA0 {enum_name("theta_network_start")}
#define CC_VR_THETA_MU {enum_name(FRICTION_OUTPUT)} /* mu is read at the friction surface (clutch_core.c) */

/* the one range of every node temperature, K (thermal_chain.NODE_RANGE) */
#define TN_THETA_MIN_K {float(NODE_RANGE[0])!r}
#define TN_THETA_MAX_K {float(NODE_RANGE[1])!r}
#ifdef CC_DEFINE_THERMAL_TABLE /* clutch_thermal.c */
{chr(10).join(arrays)}
#endif
"""


def thermal_header(chain: Chain, p: "clutch_model.ClutchParameters | None" = None) -> str:
    """Text of the variant's ``cushion_variables.h``."""
    base, extra = thermal_variables(chain)
    return variable_header(p, variant=((*base, *extra), thermal_starts(chain, p), thermal_ranges(chain)),
                           block=_block(chain))
