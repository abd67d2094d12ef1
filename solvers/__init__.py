"""Built-in schedulers for fcplan.

Each scheduler uses only fcplan's public API and is registered by name in the
``fcplan.schedulers`` entry-point group (see ``pyproject.toml``):

* ``greedy`` (:class:`solvers.greedy.GreedyScheduler`): value-per-travel-time assignment of
  action agents to fresh fires, with perception agents watching the fires being fought and
  exploring stale areas;
* ``cbba`` (:class:`solvers.cbba.CBBAScheduler`): the consensus-based bundle algorithm run as
  decentralised agents within the scenario's communication range (dump auction, then sensing);
* ``idle`` and ``random`` (:mod:`solvers.baselines`): lower baselines.
"""
