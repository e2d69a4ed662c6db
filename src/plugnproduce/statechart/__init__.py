"""The project's one SCXML layer: schema validation, model, reader, writer and runtime."""
