"""What made a launch study's outputs (scenario, version, command): written on every plot and into the output
set's manifest. Its own module so that the report and the plots both take it from below."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Provenance:
    """What made a launch study's outputs: written on every plot and into the output set's manifest."""

    scenario: str
    """the scenario's ``name``"""
    command: str = ""
    """the command line that ran it (empty: not from the command line)"""
    hot_degC: float | None = None
    """the scenario's ``run.hot_degC``: a launch is hot when theta_cs at its start is at least this, degC
    (None: not known, the plots say "the scenario's hot threshold")"""
    version: str = ""
    """cushion-clutch's version (empty: the installed package's)"""

    def line(self) -> str:
        """One line for a plot's footer: scenario, version and command."""
        return (f"scenario '{self.scenario}' · cushion-clutch {self.version or _version()}"
                + (f" · {self.command}" if self.command else ""))

    def as_dict(self) -> dict:
        """The manifest's entries."""
        return {"scenario": self.scenario, "version": self.version or _version(), "command": self.command}


def _version() -> str:
    from ... import __version__
    return __version__
