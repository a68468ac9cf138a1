"""Epoch chunks: what is computed elementwise over satellites x epochs (every value from the same
epoch's inputs) is computed a slice of epochs at a time, so that its temporaries have a chunk's
size, not the drive's. A fast-rate hour's satellite x epoch array is tens of megabytes, and
fresh memory of that size comes from the kernel, which clears it page by page at every
allocation: for a 10 Hz hour that clearing cost as much CPU as the whole geometry. The values
are the same whatever the chunk (elementwise operations do not see their neighbours); what
runs along the epochs (the random processes, the carrier smoothing, the phase arcs) still sees
the whole drive.

Public names
------------
CHUNK_EPOCHS, epoch_chunks.
"""

from __future__ import annotations

CHUNK_EPOCHS = 3600  # epochs evaluated together: an hour at 1 Hz is one chunk


def epoch_chunks(n_epoch: int, size: int | None = None) -> list[slice]:
    """Slices of at most ``size`` epochs (default ``CHUNK_EPOCHS``, read at the call) covering
    0 .. n_epoch - 1 in order."""
    size = CHUNK_EPOCHS if size is None else size
    return [slice(start, min(start + size, n_epoch)) for start in range(0, n_epoch, size)]
