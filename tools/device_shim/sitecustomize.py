# The lent GPU machine's numba-cuda reads numpy.row_stack, which numpy 2.5 removed: give it the alias.
import numpy

if not hasattr(numpy, "row_stack"):
    numpy.row_stack = numpy.vstack
