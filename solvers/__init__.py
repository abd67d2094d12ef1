"""Built-in schedulers for fcplan.

Each scheduler uses only fcplan's public API and is registered by name in the
``fcplan.schedulers`` entry-point group (see ``pyproject.toml``):

* ``greedy`` (:class:`solvers.greedy.GreedyScheduler`): value-per-travel-time assignment of
  action agents to fresh fires, with perception agents watching the fires being fought and
  exploring stale areas;
* ``routing`` (:class:`solvers.routing.RoutingScheduler`): one prize-collecting vehicle routing
  model per role on OR-Tools (drop penalties = task values, tank and battery dimensions), under a
  time limit or, for reproducible benchmarks, a solution limit;
* ``milp`` (:class:`solvers.milp.MilpScheduler`) and ``milp-cvxpy``
  (:class:`solvers.milp_cvxpy.MilpCvxpyScheduler`): the joint perception-action assignment MILP of
  :mod:`solvers.milp_model` (slots, coupling of dumps to fresh sensing, tank and battery rows),
  solved by OR-Tools CP-SAT or by HiGHS through cvxpy;
* ``cbba`` (:class:`solvers.cbba.CBBAScheduler`): the consensus-based bundle algorithm run as
  decentralised agents within the scenario's communication range (dump auction, then sensing);
* ``idle`` and ``random`` (:mod:`solvers.baselines`): lower baselines.
"""
