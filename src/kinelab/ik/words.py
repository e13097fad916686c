"""The words an IK request takes, importable without NumPy or Pinocchio (the command line's parsers offer them as
choices before anything heavy loads): the tasks and the tool axes (see :mod:`kinelab.ik.tasks`)."""

TASKS = ("pose", "position", "axis", "orientation")
AXES = ("x", "y", "z")
