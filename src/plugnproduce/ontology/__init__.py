"""The ontology: vocabulary terms and the taxonomy closure computed by the DL reasoner.

The names are imported on first use: the vocabulary's terms are rdflib's, which a command answering from its
cache folder does not load.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names

if TYPE_CHECKING:
    from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy
    from plugnproduce.ontology.vocabulary import DEV, PNP, PROC

__getattr__, __dir__ = lazy_names(__name__, {
    **dict.fromkeys(("Taxonomy", "load_taxonomy"), ".taxonomy"),
    **dict.fromkeys(("DEV", "PNP", "PROC"), ".vocabulary"),
})

__all__ = ["DEV", "PNP", "PROC", "Taxonomy", "load_taxonomy"]
