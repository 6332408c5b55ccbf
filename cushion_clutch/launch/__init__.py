"""Launch simulations: scenario -> driveline and TCU around the clutch FMU -> metrics and report."""
