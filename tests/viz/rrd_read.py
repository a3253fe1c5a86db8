"""Read a .rrd back with rerun's own reader (rr.chunk.RrdReader) into plain arrays."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr

TIMELINE = "sim_time"


@dataclass
class EntityData:
    """Temporal rows of one entity sorted by sim time, and its static columns."""

    time_ns: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    columns: dict[str, list] = field(default_factory=dict)
    static: dict[str, list] = field(default_factory=dict)

    def scalars(self) -> np.ndarray:
        values = self.columns.get("Scalars:scalars", [])
        return np.array([v[0] for v in values], dtype=np.float64)

    def points(self) -> np.ndarray:
        return np.array([v[0] for v in self.columns["Points2D:positions"]], dtype=np.float64)

    def strips(self) -> list[list[np.ndarray]]:
        """Per row, its line strips, each (m, 2)."""
        return [[np.array(s, dtype=np.float64) for s in row]
                for row in self.columns["LineStrips2D:strips"]]

    def segment_ends(self) -> np.ndarray:
        """(n, 2): the end point of each row's (single) segment."""
        return np.array([row[0][-1] for row in self.strips()])

    def segment_starts(self) -> np.ndarray:
        return np.array([row[0][0] for row in self.strips()])


def _rows(batch: pa.RecordBatch) -> dict[str, list]:
    return {name: batch.column(name).to_pylist() for name in batch.schema.names
            if name not in (TIMELINE, "rerun.controls.RowId")}


def read_recording(path: Path) -> dict[str, EntityData]:
    """Entity path -> data of the first recording store of ``path``."""
    parts: dict[str, list[tuple[np.ndarray, dict[str, list]]]] = defaultdict(list)
    out: dict[str, EntityData] = defaultdict(EntityData)
    for chunk in rr.chunk.RrdReader(path).stream().to_chunks():
        batch = chunk.to_record_batch()
        if chunk.is_static:
            out[chunk.entity_path].static.update(_rows(batch))
            continue
        t = batch.column(TIMELINE).cast(pa.int64()).to_numpy()
        parts[chunk.entity_path].append((t, _rows(batch)))
    for path_, chunks in parts.items():
        t = np.concatenate([c[0] for c in chunks])
        order = np.argsort(t, kind="stable")
        names = set().union(*(c[1] for c in chunks))
        cols = {n: [v for c in chunks for v in c[1].get(n, [None] * len(c[0]))] for n in names}
        out[path_].time_ns = t[order]
        out[path_].columns = {n: [vals[i] for i in order] for n, vals in cols.items()}
    return dict(out)


def view_origins(path: Path) -> dict[str, str]:
    """Display name -> space origin of every view of the stored default blueprint."""
    reader = rr.chunk.RrdReader(path)
    views: dict[str, str] = {}
    for entry in reader.blueprints():
        for chunk in reader.stream(store=entry).to_chunks():
            batch = chunk.to_record_batch()
            if "ViewBlueprint:space_origin" in batch.schema.names:
                names = batch.column("ViewBlueprint:display_name").to_pylist()
                origins = batch.column("ViewBlueprint:space_origin").to_pylist()
                views.update({n[0]: o[0] for n, o in zip(names, origins, strict=True)})
    return views


def tick_scale(data: dict[str, EntityData], path: str, axis: int) -> float:
    """Stored units per plotted unit, from a view's tick labels (value -> stored position).

    Asserts that every tick sits at label x scale (y ticks: negated, rerun's y points down).
    """
    static = data[path].static
    values = np.array([float(v) for v in static["Points2D:labels"][0]])
    stored = np.array(static["Points2D:positions"][0], dtype=np.float64)[:, axis]
    stored = stored if axis == 0 else -stored
    scale = float(values @ stored / (values @ values))
    np.testing.assert_allclose(stored, values * scale, rtol=1e-5, atol=1e-6 * abs(scale))
    return scale


def view_bounds(path: Path) -> dict[str, tuple[list[float], list[float]]]:
    """Space origin -> stored visual bounds (x_range, y_range) of every 2D view."""
    reader = rr.chunk.RrdReader(path)
    origins: dict[str, str] = {}
    bounds: dict[str, tuple[list[float], list[float]]] = {}
    for entry in reader.blueprints():
        for chunk in reader.stream(store=entry).to_chunks():
            batch = chunk.to_record_batch()
            if "ViewBlueprint:space_origin" in batch.schema.names:
                origins[chunk.entity_path] = batch.column(
                    "ViewBlueprint:space_origin").to_pylist()[0][0]
            if "VisualBounds2D:range" in batch.schema.names:
                value = batch.column("VisualBounds2D:range").to_pylist()[0][0]
                view = chunk.entity_path.rsplit("/", 1)[0]
                bounds[view] = (value["x_range"], value["y_range"])
    return {origins[view]: b for view, b in bounds.items()}


def series_aggregation(data: dict[str, EntityData], path: str) -> int | None:
    """The stored SeriesLines aggregation policy of a time series (enum value)."""
    values = data[path].static.get("SeriesLines:aggregation_policy")
    return None if not values else int(values[0][0])
