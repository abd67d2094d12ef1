"""What the batched environments share: autoreset modes, seeds and end-of-episode infos.

:class:`BatchedEnv` is the ``gymnasium.vector.VectorEnv`` base of
:class:`fcplan.env.vector_motion.VectorMotionEnv` and :class:`fcplan.env.vector_task.VectorTaskEnv`.
It keeps the autoreset mode (Gymnasium's three: the step after an episode's end resets the world
and returns its reset observation with reward 0; or the reset happens in the same step, the final
observation and infos going into ``final_obs``/``final_info``; or finished worlds are held until
``reset(options={"reset_mask": mask})``), turns ``reset``'s arguments into per-world seeds and
builds the per-world end-of-episode infos as Gymnasium's vector envs do (an object array and its
``_key`` mask).

Examples
--------
>>> autoreset_from("same_step").value
'SameStep'
>>> reset_rows(4, None, {"reset_mask": [True, False, False, True]}).tolist()
[0, 3]
>>> reset_seeds(4, np.array([0, 3]), 10)
[10, 13]
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv

from fcplan.batch.streams import world_seeds
from fcplan.errors import EnvError, SeedError

__all__ = [
    "AUTORESET_MODES",
    "BatchedEnv",
    "autoreset_from",
    "reset_rows",
    "reset_seeds",
    "per_world_info",
]

#: accepted ``autoreset_mode`` values (or Gymnasium's :class:`~gymnasium.vector.AutoresetMode`)
AUTORESET_MODES = ("next_step", "same_step", "disabled")


def autoreset_from(mode: str | AutoresetMode) -> AutoresetMode:
    """The :class:`gymnasium.vector.AutoresetMode` named ``mode``."""
    if isinstance(mode, AutoresetMode):
        return mode
    names: dict[str, AutoresetMode] = dict(zip(AUTORESET_MODES, AutoresetMode, strict=True))
    names.update({m.value: m for m in AutoresetMode})
    if mode not in names:
        raise EnvError(
            f"autoreset_mode: must be one of {', '.join(AUTORESET_MODES)} (got {mode!r})"
        )
    return names[mode]


def reset_rows(num: int, seed: Any, options: dict[str, Any] | None) -> np.ndarray:
    """The worlds a ``reset(seed=..., options=...)`` resets: ``options["reset_mask"]`` or all."""
    mask = None if not options else options.get("reset_mask")
    if mask is None:
        return np.arange(num)
    try:
        return np.flatnonzero(np.asarray(mask, dtype=bool).reshape(num))
    except ValueError:
        raise EnvError(f"options['reset_mask']: must be {num} booleans") from None


def reset_seeds(num: int, rows: np.ndarray, seed: Any) -> list[Any]:
    """The seed of each world of ``rows`` that ``reset(seed=seed)`` resets: Gymnasium's rule,
    :func:`fcplan.batch.streams.world_seeds` (an int ``s`` gives world ``b`` the seed ``s + b``
    whichever worlds are reset; a list holds one seed per world, or one per world reset).

    Raises
    ------
    EnvError
        For a list of another length.
    """
    try:
        return world_seeds(num, rows, seed)
    except SeedError:
        raise
    except ValueError as exc:
        raise EnvError(str(exc)) from None


def per_world_info(mask: np.ndarray, value: Callable[[int], Any]) -> tuple[np.ndarray, np.ndarray]:
    """``(values, mask)`` of a per-world info: ``value(b)`` for the worlds of ``mask``."""
    out = np.empty(mask.size, dtype=object)
    for b in np.flatnonzero(mask).tolist():
        out[b] = value(b)
    return out, mask.copy()


class BatchedEnv(VectorEnv):
    """Autoreset bookkeeping of a batched vector env (module docstring)."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def _setup(self, num_envs: int, autoreset_mode: str | AutoresetMode) -> None:
        if int(num_envs) < 1:
            raise EnvError(f"num_envs: must be >= 1 (got {num_envs})")
        self.num_envs = int(num_envs)
        self.autoreset_mode = autoreset_from(autoreset_mode)
        self.metadata = {**self.metadata, "autoreset_mode": self.autoreset_mode}
        #: next-step mode: worlds whose episode ended on the last step (reset on this one)
        self._pending = np.zeros(self.num_envs, dtype=bool)
        self._started = False

    def _stepping(self, done: np.ndarray) -> np.ndarray:
        """(B,) bool: the worlds this step advances (not reset by next-step autoreset, not held)."""
        if not self._started:
            raise EnvError("step: call reset() first")
        if self.autoreset_mode is AutoresetMode.NEXT_STEP:
            return ~self._pending
        return ~done

    def _ended(self, ended: np.ndarray) -> None:
        """Note the worlds whose episode ended on this step (next-step autoreset)."""
        self._pending = (
            ended.copy()
            if self.autoreset_mode is AutoresetMode.NEXT_STEP
            else (np.zeros(self.num_envs, dtype=bool))
        )

    def close_extras(self, **kwargs: Any) -> None:
        """Nothing to release."""
