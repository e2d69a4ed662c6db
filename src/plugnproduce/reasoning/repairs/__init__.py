"""Repair: the cheapest edits that make an implausible task plausible (whole task, windows, lifted
loops), their side effects and ranking, and the impact of an ontology edit."""
