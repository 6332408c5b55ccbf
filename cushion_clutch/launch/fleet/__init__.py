"""A fleet of sampled vehicles (:mod:`.population`, :mod:`.run`), duty limits (:mod:`.duty`) and single
engagements of the clutch FMU (:mod:`.engagements`)."""
