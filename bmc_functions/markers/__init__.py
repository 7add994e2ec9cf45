"""Markers before any body model: which is which, their gaps, their noise, their clusters.

- :mod:`.roles`: the marker roles of the lower-limb model and a lab's label mapping.
- :mod:`.gap_filling`: gaps filled with a cluster's rigid-body model.
- :mod:`.filtering`: low-pass filtering and derivatives of trajectories with gaps.
- :mod:`.tracking`: landmarks calibrated in a static trial and reconstructed from a
  tracked cluster.
"""
