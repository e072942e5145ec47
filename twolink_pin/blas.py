"""One BLAS thread for the toolkit's small dense linear algebra.

numpy's OpenBLAS starts a thread per core for every SVD, QR or least-squares solve, and
its idle threads spin. The toolkit's matrices are small (an excitation's observation matrix
is 600 × 48, an identification's a few thousand rows by 48 columns): threads gain nothing
there, and on a machine whose cores are busy with other work the spinning threads took the
cores the working one needed — measured on 2 cores at load average 11, one 600 × 48 SVD
took 320 ms of wall time on OpenBLAS's threads against 4 ms on one, which made
``excite --robot ur5`` six times slower than documented. :func:`one_blas_thread` limits
BLAS to one thread for a block (``threadpoolctl``, which finds the BLAS numpy and scipy
loaded and restores its thread count afterwards).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with BLAS (numpy's, scipy's) on one thread; the count is restored after."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
