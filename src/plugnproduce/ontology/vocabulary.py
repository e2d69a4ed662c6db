"""The ontology's vocabulary as rdflib namespaces; a misspelt term is an error."""

from __future__ import annotations

from rdflib import Namespace, URIRef
from rdflib.namespace import DefinedNamespace

from plugnproduce.ontology.iris import PNP_IRI as PNP_IRI
from plugnproduce.ontology.iris import concept_iri as concept_iri
from plugnproduce.ontology.iris import concept_value as concept_value
from plugnproduce.ontology.iris import local_name as local_name

DEV = Namespace("http://plugnproduce.org/devices/")
PROC = Namespace("http://plugnproduce.org/processes/")


class PNP(DefinedNamespace):
    """Terms of the Plug'n'Produce ontology that the code refers to by name."""

    _NS = Namespace(PNP_IRI)
    _fail = True

    Device: URIRef
    Skill: URIRef
    StateConcept: URIRef
    SafeStop: URIRef
    Process: URIRef
    Role: URIRef
    Parameter: URIRef
    Output: URIRef
    Quantity: URIRef
    Protocol: URIRef
    Task: URIRef
    Step: URIRef
    Pose: URIRef
    XIRP: URIRef
    UPnP: URIRef
    OPCUA: URIRef
    hasSkill: URIRef
    protocol: URIRef
    endpoint: URIRef
    stateChart: URIRef
    generalChart: URIRef
    commandTimeout: URIRef
    cost: URIRef
    hasRole: URIRef
    roleName: URIRef
    requiresSkill: URIRef
    hasParameter: URIRef
    parameterName: URIRef
    hasOutput: URIRef
    outputName: URIRef
    forRole: URIRef
    quantity: URIRef
    datatype: URIRef
    unit: URIRef
    minValue: URIRef
    maxValue: URIRef
    defaultValue: URIRef
    startState: URIRef
    endState: URIRef
    hasState: URIRef
    stateId: URIRef
    concept: URIRef
    sourceLine: URIRef
    mandatoryState: URIRef
    # a device's contracts for its requests' arguments
    RequestArgument: URIRef
    hasArgument: URIRef
    request: URIRef
    required: URIRef
    maxReach: URIRef
    hasDuration: URIRef
    forRequest: URIRef
    seconds: URIRef
    motionOf: URIRef
    topSpeed: URIRef
    speedShare: URIRef
    # task description lifted to RDF (for the task shapes)
    hasStep: URIRef
    stepIndex: URIRef
    command: URIRef
    hasValue: URIRef
    parameter: URIRef
    value: URIRef
