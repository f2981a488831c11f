"""Stopping a run from another thread, at the end of one of its blocks, keeping what it
computed: Ctrl-C in `jaxcable run` (`jaxcable._cli`). Plain Python: the command line
holds one before it imports JAX."""

import threading


class StopRequest:
    """A request that a run integrated in blocks (`jaxcable._simulation.blocks`) stop at
    the end of its current block and hand back what it computed, made from another
    thread."""

    def __init__(self):
        self._asked = threading.Event()
        self._keeping = threading.Event()

    def ask(self) -> bool:
        """Ask the run to stop. Returns whether it will, keeping its results: `False`
        until a run has finished its first block (it is still reading, solving statics
        or compiling), when there is nothing to keep and no block end may come soon."""
        self._asked.set()
        return self._keeping.is_set()

    @property
    def asked(self) -> bool:
        """Whether a stop was asked for."""
        return self._asked.is_set()

    def keeping(self) -> None:
        """Said by the run once a block has finished: from now a stop keeps results."""
        self._keeping.set()
