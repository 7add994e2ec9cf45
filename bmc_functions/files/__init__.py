"""The file formats: what a lab's systems write, read into tables, and written back.

- :mod:`.marker_table`: the marker table every reader returns (frames × markers × x, y, z).
- :mod:`.trc`: TRC marker files in and out (:mod:`.trc_rows`: their data rows).
- :mod:`.c3d`: marker trajectories from C3D files.
- :mod:`._c3d_binary`: a C3D file's structure checked against its length before a C3D
  library reads it (a damaged file is refused, never turned into numbers).
- :mod:`.c3d_parameters`: a C3D file's parameters and the model outputs Nexus stores.
- :mod:`.force_plates`: a C3D file's force plates (force, centre of pressure, free
  moment in the lab frame), resampled as Vicon does, and the foot on each plate.
- :mod:`.opensim`: OpenSim .mot/.sto motion files.
- :mod:`.vsk`: Vicon subject files (.vsk).
- :mod:`.trial`: one trial of any of these, loaded with its units in millimetres.
"""
