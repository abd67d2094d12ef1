"""The tutorial pages of ``fcplan play``: the controls, the team and the scores, in plain lines.

The manual's GUI shows a tutorial from the welcome screen and before every open-world game;
:data:`TUTORIAL` holds its pages as ``(title, lines)``. A line starting with three spaces
continues the line before it (the screen indents and dims it).

Examples
--------
>>> [title for title, _ in TUTORIAL]
['Controls', 'The team', 'Scores']
"""

from __future__ import annotations

__all__ = ["TUTORIAL"]

TUTORIAL: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "Controls",
        (
            "Keys 1-9 select an agent (P = perception, A = action, H = hybrid).",
            "Click on the map to add a goal at the end of the selected agent's route.",
            "Click near the route's first goal to close a patrol loop (two goals or more).",
            "A later click replaces the loop with a new route.",
            "Up / Down: raise or lower a perception or hybrid agent by 5 m.",
            "   Higher = a larger field of view but less reliable sensing (100 % -> 40 %).",
            "Click on the agent base (depot) to send the selected agent home.",
            "Space pauses, Esc ends the game early. Every game is recorded.",
        ),
    ),
    (
        "The team",
        (
            "Perception agents (blue circles) find fire: only fire the team has sensed is shown.",
            "Action agents (yellow triangles) put out sensed fire: one water dump per goal",
            "   reached, over their field of view (the box), 90 % of the cells each time.",
            "Hybrid agents (violet diamonds) do both, pruning with 80 % confidence.",
            "Agents return to the base on low battery or an empty tank, recharge and refill,",
            "   then resume their route. An action agent idle at its last goal for 3 s goes home.",
            "The panel shows battery now and at the last planned goal, altitude and tank.",
        ),
    ),
    (
        "Scores",
        (
            "Negative reward: 0.1 per burning cell per second, plus the facility penalty",
            "   (house 1, hospital 2, power station 5, base 5) per burning cell inside it.",
            "OFS: pruned / all fire.  PS: sensed / all fire.  AS: pruned / sensed fire.",
            "FPS: facilities never on fire.  NRR: negative reward / expected without pruning.",
            "Final score = PS + AS + FPS - 3 NRR.",
            "Grades: Excellent >= 90, Well Done >= 80, Almost There! >= 60, Fair >= 50.",
        ),
    ),
)
"""Tutorial pages: (title, lines)."""
