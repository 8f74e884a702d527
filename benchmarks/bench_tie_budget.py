"""The figures behind the tie-breaking budget (``api.TIE_SHARE``, ``api.TIE_GRACE_POLLS``).

    python benchmarks/bench_tie_budget.py           # every case of dump_plans.py, objective worst
    python benchmarks/bench_tie_budget.py --quick   # without the largest mixes

The ``worst`` objective's tie-breaking stages get a budget of polls (a
:class:`~feederkit.planning.budget.WorkBudget`, docs/planning.md "Which plan among the
shortest"), a multiple of the length proof's polls. Per case, with the budget lifted: the
length proof's polls and CPU seconds, the tie-breaking stages' polls and CPU seconds, the
share they would need (``(tie polls - TIE_GRACE_POLLS) / proof polls``) and whether the
default budget (``TIE_SHARE`` for both stages, ``api.EXPECTED_SHARE`` for the second) cuts
them short. The last lines give each phase's polls per CPU second over
every case that polls at least a thousand times, the ratio that turns the poll budget into
seconds.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_planners as bp  # noqa: E402
import dump_plans as dp  # noqa: E402

import feederkit.planning.api as api  # noqa: E402
from feederkit.errors import PlanningError  # noqa: E402
from feederkit.planning.budget import Deadline, WorkBudget  # noqa: E402


class _Recording(WorkBudget):
    """The tie-breaking budgets of one plan (the stages', then the expected stage's share),
    remembering the length proof's polls and the CPU clock."""

    made: list[_Recording] = []

    def __init__(self, outer: Deadline, polls: float) -> None:
        super().__init__(outer, polls)
        self.proof_polls = outer.polls
        self.cpu_start = time.process_time()
        _Recording.made.append(self)


def main(argv: list[str]) -> int:
    share, grace, eshare = api.TIE_SHARE, api.TIE_GRACE_POLLS, api.EXPECTED_SHARE
    api.WorkBudget = _Recording
    api.TIE_SHARE = api.EXPECTED_SHARE = 1e9  # lifted: every case's stages run to the end
    proof_rate, tie_rate = [0, 0.0], [0, 0.0]
    print(
        f"default budget: {share:g} x proof polls + {grace} polls, of which the expected "
        f"stage at most {eshare:g} x proof polls + {grace}"
    )
    print(f"{'proof polls':>11} {'CPU s':>6} {'tie polls':>9} {'CPU s':>6} {'share':>7}  case")
    for name, machine, options in dp.cases("--quick" in argv):
        if options.objective.value != "worst":
            continue
        _Recording.made = []
        start = time.process_time()
        try:
            api.plan(bp.fresh(machine), options)
        except PlanningError:
            print(f"{'':>11} {'':>6} {'':>9} {'':>6} {'':>7}  {name}: no plan")
            continue
        end = time.process_time()
        if not _Recording.made:
            print(f"{'':>11} {'':>6} {'':>9} {'':>6} {'':>7}  {name}: no tie-breaking stage")
            continue
        budget = _Recording.made[0]
        proof, ties = budget.proof_polls, sum(b.polls for b in _Recording.made)
        proof_s, ties_s = budget.cpu_start - start, end - budget.cpu_start
        need = (ties - grace) / max(proof, 1)
        expected = sum(b.polls for b in _Recording.made[1:])
        over = ties > share * proof + grace or expected > eshare * proof + grace
        cut = " (cut short by default)" if over else ""
        print(f"{proof:11d} {proof_s:6.2f} {ties:9d} {ties_s:6.2f} {need:7.2f}  {name}{cut}")
        if proof >= 1000 or ties >= 1000:
            proof_rate[0] += proof
            proof_rate[1] += proof_s
            tie_rate[0] += ties
            tie_rate[1] += ties_s
    for label, (polls, seconds) in (("length proof", proof_rate), ("tie-breaking", tie_rate)):
        if seconds > 0:
            print(f"{label}: {polls / seconds:,.0f} polls per CPU second")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
