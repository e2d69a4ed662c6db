"""What the command line needs besides its commands: typer option coercion without pydantic, help text
and its layout, progress on a terminal, and input and output through pipes."""
