"""Sending the task functions to the cluster by value, not by name.

Dask pickles a task graph with plain `pickle` whenever it can, and plain
pickle names a function by its module ('cirrus_farm.worker_tasks'), which
the scheduler and every worker would then have to import. Wrapped here,
a function travels as its own code instead (cloudpickle, by value), so
the cluster needs `distributed` and the cirrus binary, not this package.
"""

from __future__ import annotations

import pickle
from types import ModuleType
from typing import Any, Callable

import cloudpickle


class ShippedByValue:
    """A callable that unpickles, wherever it goes, as the function it wraps.

    The function must live in a module whose own imports are all standard
    library (see `worker_tasks`), since those are still pickled by name.
    """

    def __init__(self, function: Callable[..., Any], module: ModuleType):
        self.function = function
        self.__name__ = function.__name__
        cloudpickle.register_pickle_by_value(module)
        try:
            self._code = cloudpickle.dumps(function)
        finally:
            cloudpickle.unregister_pickle_by_value(module)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.function(*args, **kwargs)

    def __reduce__(self):
        return pickle.loads, (self._code,)
