"""simsr: physics-based simulation super-resolution, the C++ library in Python.

Every function that runs parallel code takes the execution policy as the keyword
``policy="omp"`` (the default) or ``policy="seq"``; long calls release the GIL. Errors are
``simsr.Error`` subclasses carrying the library's messages and fields (``simsr.ParseError.file``,
``.line``; ``simsr.ShapeError.expected``, ``.got``; ...).

Copies: ``(N, 3)`` frames passed to ``apply`` are read in place when they are C-contiguous
float64 (other dtypes or layouts are converted once); ``apply(..., out=a)`` writes into ``a``;
returned arrays take over the library's buffers; array attributes (``TetMesh.V``,
``KnnResult.indices``, ...) are views into their object; meshes and training frames are copied
into the objects that keep them.
"""
from ._simsr import *  # noqa: F401,F403  (the compiled module's public names)
from ._simsr import __doc__ as _compiled_doc, __version__  # noqa: F401

from ._simsr import _method_classes


def make_method(name, **options):
    """The interpolation baseline called ``name`` (one of ``method_names()``), built with ``options``
    (the fields of its C++ options struct), as ``simsr upsample --method NAME`` builds it."""
    try:
        cls = _method_classes[name]
    except KeyError:
        raise ArgumentError(f"unknown method '{name}' (known: {', '.join(method_names())})") from None
    return cls(**options)
