"""C3D files: ``layout`` (header and parameter section, validated before any data is
decoded), ``decode`` (the data section), ``read`` (points, analogs, events into a Trial),
``forceplates``, ``rotations`` (markerless segment poses), ``parameters`` and ``write``."""
