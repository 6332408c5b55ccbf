"""The launch's plant: the engine, the compliant driveline, the clutch FMU's client, the compiled plant block,
the production TCU's sensor hardware and the lumped facing model; :mod:`.build` makes the plant FMU."""
