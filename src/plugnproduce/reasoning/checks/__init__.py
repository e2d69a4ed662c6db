"""The check: the process commands a cell offers and the plausibility of a task on it — roles, branches,
data flow, control flow, the devices' contracts and accepted values, link safety and catalogue abilities."""
