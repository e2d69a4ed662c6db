"""Quantities and their limits in descriptions: units (pint, through a kept table), value ranges, the
argument contracts of requests and processes, request durations, and the values a device reports with its state."""
