"""The rigid-body maths under every layer: rotations, Cardan angles, frames, the SVD fit.

- :mod:`.rotations`: elemental rotations, the rotation that takes one vector onto another,
  the rotation angle of a matrix.
- :mod:`.cardan`: Cardan/Euler angles of a rotation matrix, and back.
- :mod:`.frames`: orthonormal frames from axes and points.
- :mod:`.svdt`: the least-squares rigid-body transformation of two marker sets (SVD),
  with :mod:`.quaternion_fit` its closed-form fast path.
- :mod:`.clusters`: how precisely a cluster's geometry fixes its orientation.
- :mod:`.motion`: angular velocity and helical axes.

Nothing here knows about files, markers' names or bodies; the layers above use it.
"""
