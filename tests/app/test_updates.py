"""One computation at a time per page (qzs.app.updates): the newest request only, a superseded
result dropped, errors delivered, a cancelled request never delivered."""
from helpers import HeldExecutor

from qzs.app.updates import LatestOnly
from qzs.errors import ParameterError


def test_latest_only_drops_superseded_results():
    delivered, busy = [], []
    executor = HeldExecutor()
    updates = LatestOnly(lambda r: r * 10, lambda r, out: delivered.append((r, out)),
                         executor=executor, schedule=lambda f: f(), busy=busy.append)
    updates.submit(1)
    updates.submit(2)           # waits
    updates.submit(3)           # replaces 2, which is never computed
    assert len(executor.jobs) == 1 and updates.running
    executor.finish()           # 1 is done: superseded, dropped; 3 starts
    assert delivered == [] and updates.dropped == 1
    assert [job[2] for job in executor.jobs] == [3]
    executor.finish()
    assert delivered == [(3, 30)] and not updates.running
    assert busy == [True, False] and updates.delivered == 1


def test_latest_only_delivers_errors_and_cancels():
    delivered = []
    executor = HeldExecutor()

    def compute_or_fail(request):
        if request < 0:
            raise ParameterError("negative")
        return request

    updates = LatestOnly(compute_or_fail, lambda r, out: delivered.append(out),
                         executor=executor, schedule=lambda f: f())
    updates.submit(-1)
    executor.finish()
    assert isinstance(delivered[0], ParameterError)
    updates.submit(5)
    updates.cancel()            # the page's values became invalid meanwhile
    executor.finish()
    assert len(delivered) == 1 and updates.dropped == 1 and not updates.running


