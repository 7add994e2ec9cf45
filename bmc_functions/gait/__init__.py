"""Gait cycles: events from markers and from force plates, cycles, ensembles, parameters.

- :mod:`.events`: heel strike and toe-off from markers.
- :mod:`.cycles`: time normalisation between heel strikes, ensembles, spatio-temporal
  parameters (:mod:`.strides`: each stride's phases and lengths, Vicon's definitions).
- :mod:`.gait_profile`: a lab's normative data, the Gait Profile Score and the Movement
  Analysis Profile.
- :mod:`.event_files`: gait events stored beside a trial (the C3D EVENT group, a CSV
  file), read and written.
- :mod:`.force_plates`: the reference events of force plates, and how marker events
  compare.
- :mod:`.plate_events`: force plates first in :func:`.events.gait_events` (``force_plates=``):
  the plates' events, and the marker events calibrated on them.
"""
