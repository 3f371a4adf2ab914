"""``cellstress verify``: every sequence of the worker's actions decided exactly, by dynamic programming over the
simulator's states (``tree``), with sound pruning bounds (``bounds``, ``reach``), for every start point and
arrival phase (``phases``), in worker processes (``run``); typed records (``records``) and replayable witnesses
(``witness``). The API function is ``cellstress.verify``; docs/verify.md gives the arguments."""
