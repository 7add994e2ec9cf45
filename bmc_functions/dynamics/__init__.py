"""Dynamics: segment inertial parameters and Newton-Euler inverse dynamics, on arrays.

- :mod:`.segment_parameters`: Dempster's segment masses, centres of mass and radii of
  gyration (Winter 2009, Table 4.1), with a user's overrides.
- :mod:`.newton_euler`: joint reaction forces, net joint moments and joint powers of a
  chain of segments, from the foot up.

This layer sits below :mod:`bmc_functions.models`: it takes segment frames and joint
centres as arrays, and the models' ``kinetics()`` methods call it.
"""
