"""Stand-in evaluation backends for tests of what a run does when its backend fails."""

from mtpg.engine.evaluator import BackendLost, LocalEvaluator


def losing_backend(after: int, message: str = "gone") -> type[LocalEvaluator]:
    """A local evaluator that reports itself lost once it has made ``after`` evaluations.

    Like a Dask cluster whose scheduler went away during evaluation ``after``: that
    evaluation still completes (as the real backend finishes it on local threads), and
    ``check`` raises :class:`BackendLost` with ``message`` from then on.
    """

    class Losing(LocalEvaluator):
        evaluations = 0

        def evaluate(self, *args, **kwargs):
            Losing.evaluations += 1
            return super().evaluate(*args, **kwargs)

        def check(self):
            if Losing.evaluations >= after:
                raise BackendLost(message)

    return Losing
