"""The studies that drive the FE pipeline: calibration against a measured curve and tolerance
(production-scatter) studies, with their reports and plots."""
