"""The ASP layer: clingo and the typed boundary around it — ASP terms, the fact schema, facts from
descriptions, the solver over ``rules/*.lp``, answers decoded into dataclasses and reasons into sentences,
and the derivation trees the answers rest on."""
