"""The cushion spring's heat path (U, H, C of the paper's eq. 2): its one section type and its one rule.

``C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs)``: U the facings -> spring conductance,
H the spring -> ambient conductance (W/K), C the spring's heat capacity (J/K). The rule ``U + H > 0`` (the
spring exchanges heat, else its temperature has no time constant) is stated here once:
:func:`~.clutch_model.heat_path_problem` (in :mod:`.clutch_model`, which the pythonfmu FMU carries as a
sibling module) for :class:`~.clutch_model.ClutchParameters` (``U``, ``H``, ``C``) and the named sets
(:mod:`.thermal_set`), :class:`SpringHeat` for the scenario sections that carry their own copy
(the TCU's observer and its EKF network: ``spring_U_W_per_K``, ``spring_H_W_per_K``, ``spring_C_J_per_K``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ..config import Checked
from .clutch_model import ClutchParameters, heat_path_problem

#: the section's keys -> the FMU's parameters, whose allowed ranges (ClutchParameters.RANGES) they share
FMU_NAMES = {"spring_U_W_per_K": "U", "spring_H_W_per_K": "H", "spring_C_J_per_K": "C"}


@dataclass(frozen=True)
class SpringHeat(Checked):
    """A section's cushion-spring heat path (the defaults are :class:`~.clutch_model.ClutchParameters`' U, H, C).

    A mixin of checked sections: the section's ``_problems`` yields :meth:`_spring_problems`.
    """

    spring_U_W_per_K: float = 0.1
    """facings -> spring conductance, W/K"""
    spring_H_W_per_K: float = 0.04
    """spring -> ambient conductance, W/K"""
    spring_C_J_per_K: float = 1.0
    """the spring's heat capacity, J/K"""

    def _spring_problems(self) -> Iterable[str]:
        """The three ranges and the rule ``U + H > 0`` (once both ranges passed)."""
        yield from self._ranges(spec := {key: ClutchParameters.RANGES[name] for key, name in FMU_NAMES.items()})
        if self._passed(spec, "spring_U_W_per_K", "spring_H_W_per_K"):
            msg = heat_path_problem(self.spring_U_W_per_K, self.spring_H_W_per_K, "spring_U_W_per_K",
                                    "spring_H_W_per_K", self._key("spring_H_W_per_K"))
            if msg:
                yield msg

    def _problems(self) -> Iterable[str]:
        yield from self._spring_problems()

    def spring_parameters(self) -> dict[str, float]:
        """The FMU's names ``U``, ``H``, ``C`` (:class:`~.clutch_model.ClutchParameters`)."""
        return {name: getattr(self, key) for key, name in FMU_NAMES.items()}
