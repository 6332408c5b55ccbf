"""cushion_clutch: temperature-aware dry-clutch torque characteristics.

Pipeline: spring parameters (TOML) -> paddle mesh -> CalculiX deck -> ccx run
-> parsed results -> F(u, theta) and kiss-point tables -> FMU.
"""
__version__ = "0.1.0"
