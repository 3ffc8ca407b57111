"""What ``mocap info`` says about a trial: the ``docs/formats/info-json.md`` summary and its text form."""
from __future__ import annotations

import numpy as np

from mocap.errors import MocapError
from mocap.io.c3d.forceplates import describe_plates
from mocap.io.c3d.outputs import computed_positions
from mocap.trial import Trial


def gap_table(trial: Trial) -> tuple[np.ndarray, np.ndarray]:
    """Number of gaps and longest gap (frames) per marker, vectorised.

    Parameters
    ----------
    trial : Trial

    Returns
    -------
    gaps : ndarray, shape (markers,), int
        Runs of consecutive missing frames.
    longest : ndarray, shape (markers,), int
        Length of the longest run, in frames.
    """
    markers = len(trial.labels)
    missing = np.isnan(trial.points).any(axis=2).T.astype(np.int8)    # (markers, frames)
    edges = np.diff(np.pad(missing, ((0, 0), (1, 1))), axis=1)
    starts = np.argwhere(edges == 1)
    ends = np.argwhere(edges == -1)
    gaps = np.bincount(starts[:, 0], minlength=markers)
    longest = np.zeros(markers, dtype=int)
    np.maximum.at(longest, starts[:, 0], ends[:, 1] - starts[:, 1])
    return gaps, longest


def summarise(trial: Trial) -> dict:
    """The ``mocap info --json`` object of one trial (``docs/formats/info-json.md`` and extras).

    ``markers`` and their gaps are the captured markers only: the positions a model computed
    and stored as points (axis points, joint centres, centre of mass:
    :func:`mocap.io.c3d.outputs.computed_positions`) are listed in ``computed_points``.
    """
    computed = computed_positions(trial.labels) if trial.format == "c3d" else {}
    if computed:
        trial = trial.select([label for label in trial.labels if label not in computed])
    gaps, longest = gap_table(trial)
    missing = trial.missing_fraction()
    summary = {
        "path": trial.path,
        "format": trial.format,
        "rate": trial.rate,
        "frames": trial.frames,
        # None (null) when several frames have no rate to time them
        "duration": trial.duration if trial.rate > 0 or trial.frames <= 1 else None,
        "markers": list(trial.labels),
        "units": trial.units,
        "missing": missing,
        "missing_overall": float(np.mean(list(missing.values()))) if missing else 0.0,
        "gaps": {label: int(n) for label, n in zip(trial.labels, gaps)},
        "longest_gap": {label: int(n) for label, n in zip(trial.labels, longest)},
        "analog_channels": len(trial.analog_labels),
        "analog_rate": trial.analog_rate,
        "warnings": list(trial.metadata.get("warnings", [])),
    }
    if "reader" in trial.metadata:
        summary["reader"] = trial.metadata["reader"]
    if computed:
        summary["computed_points"] = computed
    if trial.modelled is not None:
        summary["modelled_points"] = list(trial.modelled["labels"])
        summary["modelled_kinds"] = list(trial.modelled["kinds"])
    if trial.events:
        summary["events"] = trial.events
    if trial.poses is not None:
        summary["rotations"] = list(trial.poses.labels)
        summary["rotation_rate"] = trial.poses.rate
    if trial.format == "c3d":
        try:
            plates = describe_plates(trial)
        except MocapError as error:
            plates = [f"not usable: {error.problem}"]
        if plates:
            summary["force_plates"] = plates
    return summary


def _output_counts(summary: dict) -> dict[str, int]:
    """Model outputs of a summary by kind (``{"axis points": 76, "angles": 55 …}``)."""
    counts: dict[str, int] = {}
    for kind in summary.get("computed_points", {}).values():
        counts[kind] = counts.get(kind, 0) + 1
    kinds = summary.get("modelled_kinds") or []
    for kind in kinds:
        counts[kind.lower()] = counts.get(kind.lower(), 0) + 1
    return counts


def format_summary(summary: dict, list_markers: bool = False) -> str:
    """Readable text form of :func:`summarise`'s dictionary."""
    markers = summary["markers"]
    with_gaps = [label for label in markers if summary["gaps"][label]]
    reader = f" (read by {summary['reader']})" if "reader" in summary else ""
    lines = [
        f"path:      {summary['path']}",
        f"format:    {summary['format']}{reader}",
        f"rate:      {summary['rate']:g} Hz" + ("" if summary["rate"] else " (none)"),
        f"frames:    {summary['frames']} ("
        + (f"{summary['duration']:.3f} s)" if summary["duration"] is not None
           else "duration unknown)"),
        f"markers:   {len(markers)}"
        + (f" ({', '.join(markers[:8])}{', …' if len(markers) > 8 else ''})" if markers
           else ""),
        f"units:     {summary['units'] or '(not stated)'}",
        f"missing:   {100 * summary['missing_overall']:.1f}% of marker-frames; "
        f"{len(with_gaps)} of {len(markers)} markers have gaps",
    ]
    if summary["analog_channels"]:
        rate = summary["analog_rate"]
        lines.append(f"analogs:   {summary['analog_channels']} channels at "
                     + (f"{rate:g} Hz" if rate else "an unknown rate"))
    if summary.get("rotations"):
        names = summary["rotations"]
        lines.append(f"rotations: {len(names)} segment poses at {summary['rotation_rate']:g} "
                     f"Hz ({', '.join(names[:8])}{', …' if len(names) > 8 else ''})")
    for k, plate in enumerate(summary.get("force_plates", [])):
        lines.append(("plates:    " if k == 0 else "           ") + plate)
    outputs = _output_counts(summary)
    if outputs:
        lines.append(f"outputs:   {sum(outputs.values())} model outputs stored as points, not "
                     f"markers: " + ", ".join(f"{n} {kind}" for kind, n in outputs.items()))
    if summary.get("events"):
        shown = ", ".join(f"{e['context']} {e['label']} {e['time']:.2f} s".strip()
                          for e in summary["events"][:6])
        more = f" … ({len(summary['events'])} in all)" if len(summary["events"]) > 6 else ""
        lines.append(f"events:    {shown}{more}")
    for warning in summary["warnings"]:
        lines.append(f"warning:   {warning}")
    shown = markers if list_markers else with_gaps
    if shown:
        width = max(len(label) for label in shown)
        lines.append("")
        lines.append(f"{'marker':<{width}}  missing  gaps  longest gap (frames)")
        for label in shown:
            lines.append(f"{label:<{width}}  {100 * summary['missing'][label]:6.1f}%  "
                         f"{summary['gaps'][label]:4d}  {summary['longest_gap'][label]:d}")
    return "\n".join(lines)
