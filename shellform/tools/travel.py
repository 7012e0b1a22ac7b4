"""How far a tool has travelled along its axis at load factor lambda: the path of a press's slide.

    Linear(rate)           dz = lambda rate: the punch (rate = -stroke), a fixed die (0)
    Capped(rate, limit)    dz = lambda rate until it reaches `limit`, then `limit`: a slide that
                           moves with the ram and stops, the blank holder of a curved binder
                           (tools.binder_rise, channel.py), which comes down with the punch
                           until its face is at its gap over the die's binder face and is
                           held there while the punch draws on

A path gives its position ``at(lam)`` and its travel from lam0 to lam1, ``between(lam0, lam1)``
(a node's tool moves by that much in an increment: friction's slip is measured relative to
it). `rate` is the travel at lambda = 1 of a slide that never stops; a run's checkpoint stores
the rates (a resume with a longer stroke rescales lambda so that the punch stays where it was:
contact.semi_inverse).
"""

from dataclasses import dataclass


@dataclass(frozen=True)
class Linear:
    rate: float

    def at(self, lam: float) -> float:
        return lam * self.rate

    def between(self, lam0: float, lam1: float) -> float:
        return (lam1 - lam0) * self.rate


@dataclass(frozen=True)
class Capped:
    rate: float
    limit: float  # the position it stops at (the same sign as rate)

    def __post_init__(self):
        if self.rate * self.limit < 0:
            raise ValueError(f"travel: the limit {self.limit} lies against the direction of travel {self.rate}")

    def at(self, lam: float) -> float:
        dz = lam * self.rate
        return max(dz, self.limit) if self.rate < 0 else min(dz, self.limit)

    def between(self, lam0: float, lam1: float) -> float:
        return self.at(lam1) - self.at(lam0)


def path(travel) -> Linear | Capped:
    """A tool's path: a Linear or Capped path as it is, or a number (the rate of a Linear one)."""
    return travel if isinstance(travel, (Linear, Capped)) else Linear(float(travel))
