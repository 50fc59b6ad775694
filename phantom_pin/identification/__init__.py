"""Identification of a PHANToM's own dynamics: regressor, base parameters, excitation,
estimation, physical consistency, and the CSV log (docs/identification.md)."""
