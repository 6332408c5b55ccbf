"""What a launch run yields: per-launch metrics (:mod:`.metrics`), plots (:mod:`.plots`) and provenance."""
