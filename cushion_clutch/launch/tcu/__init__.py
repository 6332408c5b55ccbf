"""The six TCU variants (:mod:`.controller`), their estimators and the production TCU (:mod:`.production`)."""
