"""Safety criteria, one module each, registered in the ``cellstress.criteria`` entry-point group: which states
are unsafe, and the reward that steers a search towards them.

A criterion is its cell-file record (a frozen pydantic model tagged by ``type``) with the
``core.protocols.Criterion`` methods. Built in: ``contact-while-moving`` (the paper's, ``contact``) and
``iso15066`` (force limits per body region, ``iso15066``).
"""
