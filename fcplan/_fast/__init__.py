"""Private speed kernels: bit-identical fast versions of readable code elsewhere in fcplan.

Nothing here is public API. Each kernel names the plain code it replaces (its specification)
and is tested equal to it.
"""
