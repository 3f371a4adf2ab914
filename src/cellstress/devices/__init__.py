"""Safety device kinds, one module each, registered in the ``cellstress.devices`` entry-point group.

A device kind is its cell-file record (a frozen pydantic model tagged by ``type``) with the
``core.protocols.Device`` methods: the detection primitives it gives the compiled kernel, its ISO 13855
minimum distance, and how it is described and drawn. Upon detection a device requests a stop, which takes effect
after its response time. Built in: ``laser-scanner`` (``laser_scanner``) and ``light-curtain``
(``light_curtain``).
"""
