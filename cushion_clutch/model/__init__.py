"""The clutch model: the physics once in Python, numpy only (paper eqs. 2-5).

- :mod:`.clutch_model`: the FMU interface (``VARIABLES``), parameters, outputs, thermal step;
- :mod:`.spring_table`: F(u, theta) and the kiss-point shift from a table set;
- :mod:`.cover`: the diaphragm-spring cover, finger lever and clamp load (force balance), kiss-point budget;
- :mod:`.cover_file`: the checked ``[cover]`` section of a TOML file;
- :mod:`.friction`: the optional mu(theta_cm, omega_slip) table;
- :mod:`.table_format`: the table-set format (file names, columns, units, metadata keys), its CSV reader;
- :mod:`.api`: loading a table set, torque, the thermal model as a python-control system.

The pythonfmu FMU carries ``clutch_model``, ``spring_table``, ``cover``, ``friction``, ``table_format`` and
``number_check`` (the one "is this a number, never a bool" predicate) as
sibling modules (its build copies them), so they import each other relatively with a
fallback to plain sibling imports. The FE pipeline, the FMU build, the launch
simulation and the pythonfmu slave all use these modules; nothing here imports
from the rest of the package at import time.

Examples
--------
>>> from cushion_clutch.model import load_table, ClutchParameters, outputs, x_to_for_torque
>>> table, p = load_table(), ClutchParameters()
>>> out = outputs(x_to=0.0055, theta_cs=468.15, table=table, p=p)      # 195 degC
"""
from .api import load_table, thermal_system, torque
from .clutch_model import (KELVIN, OMEGA_SLIP_LIMIT, OMEGA_SLIP_START, VARIABLES, ClutchParameters, CoverParameters,
                           Outputs, SpringTable, kiss_point, outputs, thermal_step, x_to_for_torque)

__all__ = ["KELVIN", "VARIABLES", "ClutchParameters", "CoverParameters", "Outputs", "SpringTable", "outputs", "thermal_step",
           "x_to_for_torque", "kiss_point", "OMEGA_SLIP_START", "OMEGA_SLIP_LIMIT", "load_table", "torque", "thermal_system"]
