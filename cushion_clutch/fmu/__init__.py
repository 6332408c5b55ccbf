"""The clutch FMU: the Python model API, FMU builds (native C and pythonfmu) and table exports."""
