"""Second-order forward differentiation ("jets"): exact gradients and Hessians for the element kernels.

One scalar and one vector engine, each a NumPy module and a compiled twin:

============  ==========================  ==============================================
engine        NumPy (vectorised, points)  compiled (one point, no allocation)
============  ==========================  ==============================================
scalar        :mod:`.scalar` (BE3D)       :mod:`.scalar_numba` (BE3D kernels)
vector        :mod:`.vector` (SQ frame)   :mod:`.vector_numba` (SQ kernels)
============  ==========================  ==============================================

A NumPy jet is an object holding value, gradient and Hessian for a batch of
points; a compiled jet is a slot (row) of three work arrays ``V, G, H``. The
twins share the names of their operations and the order of the operands: a
NumPy call ``mul(a, b)`` reads ``mul(V, G, H, o, a, b, ..., order)`` compiled,
with the output slot ``o`` after the work arrays and the sizes the slots cannot
tell (``n`` or ``d``) before ``order``. ``order`` is the highest derivative
propagated: 0 the value, 1 plus the gradient, 2 plus the Hessian.
"""
