"""The lines of a description an explanation rests on: the page opens the file at that line.

Only files the cell's knowledge is made of are served (the ontology, the encodings, the device and process
descriptions and their charts); any other path is a 404, so the route cannot read the rest of the disk.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi import APIRouter, Depends, HTTPException, Query, status

from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.security import allow_read
from plugnproduce.service import rules_path

router = APIRouter(prefix="/api", tags=["sources"], dependencies=[Depends(allow_read)])

AROUND = 12
"""Lines shown before and after the line asked for."""


def known_files(hub: Hub) -> set[str]:
    """Every file an explanation about the hub's cell may cite."""
    k = hub.knowledge
    out = {str(f) for f in k.ontology_files()} | {str(f) for f in rules_path().glob("*.lp")}
    for d in (*k.devices, *hub.catalogue, *hub.cell.devices):
        out |= {d.where.file, d.chart_file}
    for p in k.processes:
        out |= {p.where.file, p.chart_file}
    return out


@router.get("/source", summary="Lines of a description file around a line an explanation cites")
def source(file: str = Query(..., max_length=4096), line: int = Query(1, ge=1, le=10**7),
           hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """The file's name, the line asked for, and the lines around it (each ``{number, text}``)."""
    if file not in known_files(hub):
        raise HTTPException(status.HTTP_404_NOT_FOUND, "error: not a description file of this cell")
    lines = Path(file).read_text(encoding="utf-8").splitlines()
    first, last = max(1, line - AROUND), min(len(lines), line + AROUND)
    return {"file": file, "name": Path(file).name, "line": line,
            "lines": [{"number": n, "text": lines[n - 1]} for n in range(first, last + 1)]}
