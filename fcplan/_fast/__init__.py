"""Private speed kernels of the simulator core.

The rules of the simulation are written once, readably, in the public modules: :mod:`fcplan.team`
(motion, battery, 3-second rule, field of view, sensing confidence), :mod:`fcplan.fire` (FARSITE
fronts, ignition) and :mod:`fcplan.world` (the tick). Those rules run on numpy over whole arrays,
which is what large teams and large fires need. On the per-tick path of a normal episode (a
handful of agents, a few dozen fronts, a few fresh cells per tick) numpy's fixed cost per call
dominates, so this package holds hand-tuned versions of some of those rules: the same IEEE
operations in the same order, on Python numbers or over precomputed blocks.

The contract of every kernel here is **bit-identity with the readable rule it replaces**: same
values, same signed zeros and NaNs, same random stream. The tests in ``tests/_fast/`` (one module
per module here) run the readable rule and the kernel on the same inputs and compare the results
bit for bit. The public module decides which path runs; nothing outside fcplan's core should
import this package, and its functions may change or vanish without notice.

Modules
-------
team
    The small-team move and rules on Python floats, field-of-view rectangles and sensing confidence
    of one agent.
fire
    Wind draws computed ahead in blocks of ticks, the whole-array front step, ignition of a few
    cells on Python ints, a cheaper ``np.unique``.
world
    The :class:`~fcplan.world.StepInfo` builder and the field-of-view scan box.
taskgraph
    The task graph's dataclass constructor without ``__init__`` (``new_frozen``), tested equal
    to the plain constructor.
"""
