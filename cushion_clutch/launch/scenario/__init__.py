"""The launch scenario: its file's sections, each a checked frozen dataclass, and the loader (:mod:`.load`)."""
from .load import (DEFAULT_SCENARIO, LEVELS, Clutch, Driveline, Driver, Engine, Facing, Run, Scenario, Tcu, Vehicle,
                   load_scenario, merged_data, scenario_path, shipped_names)

__all__ = ["DEFAULT_SCENARIO", "LEVELS", "Clutch", "Driveline", "Driver", "Engine", "Facing", "Run", "Scenario", "Tcu",
           "Vehicle", "load_scenario", "merged_data", "scenario_path", "shipped_names"]
