"""The loaded knowledge: built-in and user libraries, their taxonomy, processes and catalogue."""

from __future__ import annotations

from plugnproduce.knowledge.libraries import (
    ENV_VARIABLE,
    Knowledge,
    Library,
    builtin_library,
    env_folders,
    library_folders,
    load_knowledge,
)

__all__ = ["ENV_VARIABLE", "Knowledge", "Library", "builtin_library", "env_folders", "library_folders",
           "load_knowledge"]
