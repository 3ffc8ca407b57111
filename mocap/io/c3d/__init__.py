"""C3D files: ``layout`` (header and parameter section, validated before any data is
decoded), ``read`` (points, analogs, events into a Trial) and ``write`` (with ezc3d)."""
