"""Explanation: why a command is or is not offered and a task is or is not plausible, as derivation
trees down to the OWL axioms and ASP rule instances, and the counterfactuals that would change the answer."""
