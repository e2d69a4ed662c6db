"""The ontology: vocabulary terms and the taxonomy closure computed by the DL reasoner."""

from __future__ import annotations

from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy
from plugnproduce.ontology.vocabulary import DEV, PNP, PROC

__all__ = ["DEV", "PNP", "PROC", "Taxonomy", "load_taxonomy"]
