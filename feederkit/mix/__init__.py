"""Product mixes (section 8): behaviour classes, distinguishable pairs with witnesses, look-alikes.

- :mod:`~feederkit.mix.signatures`: rotation-invariant signatures of push and push-diameter
  functions; "same" in the sense of section 8.3, with a phase shift alpha.
- :mod:`~feederkit.mix.behaviour`: classes of parts with the same push (push-diameter) function,
  by hashing signatures (no all-pairs pass).
- :mod:`~feederkit.mix.pairs`: exact distinguishability of two parts (a greatest fixpoint),
  ``PairWitness``, ``unrecognizable_pairs`` pruned by diameters.
- :mod:`~feederkit.mix.lookalike`: Theorems 4 and 6, checked constructions.
- :mod:`~feederkit.mix.analyze`: a catalog's analysis (classes, counts, pairs).
"""

from feederkit.mix.behaviour import BehaviourClass, push_classes, push_diameter_classes
from feederkit.mix.pairs import (
    CandidatePairs,
    PairWitness,
    candidate_pairs,
    distinguishable,
    inseparable_cross_pairs,
    unrecognizable_pairs,
)
from feederkit.mix.signatures import (
    ANGLE_TOL_DEG,
    LENGTH_TOL_MM,
    Signature,
    same_push_diameter_function,
    same_push_function,
    signature,
)

__all__ = [
    "ANGLE_TOL_DEG",
    "LENGTH_TOL_MM",
    "BehaviourClass",
    "CandidatePairs",
    "PairWitness",
    "Signature",
    "candidate_pairs",
    "distinguishable",
    "inseparable_cross_pairs",
    "push_classes",
    "push_diameter_classes",
    "same_push_diameter_function",
    "same_push_function",
    "signature",
    "unrecognizable_pairs",
]
