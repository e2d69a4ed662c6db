"""Simulated devices that run their own Device State Charts, and the simulated cell."""
