"""Quantities and their limits in descriptions: units (pint, through a kept table), value ranges, the
argument contracts of requests and processes, and request durations."""
