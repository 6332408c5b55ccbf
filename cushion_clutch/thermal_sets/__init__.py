"""Named cushion-spring thermal parameter sets (U, H, C of eq. 2), data files only: see
:mod:`cushion_clutch.model.thermal_set`."""
