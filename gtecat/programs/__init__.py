"""Motion programs (manual chapter 10) and the ferroelectric memory (11.8).

* :mod:`.language` - the grammar (lark) and the source checks before parsing;
* :mod:`.compiler` - the rules of 10.4, source -> :class:`.model.Program`;
* :mod:`.model` - instructions, operands, variables, functions;
* :mod:`.image` - the ``.bin`` program image and the ``.ini`` symbol file;
* :mod:`.fixed` - 32-bit ``int`` and 16.16 ``double`` arithmetic;
* :mod:`.gtcalls` - which GT functions a program may call;
* :mod:`.threads` - the controller side: memory, 32 threads, 32 pages, the scheduler;
* :mod:`.mram` - the MRAM buffer, its accesses and the atomic file store.

The GT functions over these are in :mod:`gtecat.gt.program_calls`; docs/programs.md
is the guide.
"""
