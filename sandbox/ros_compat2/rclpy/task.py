"""rclpy.task: Future and Task (rclpy/task.py).

A Future is done once set_result/set_exception/cancel is called; result() raises the exception
that was set; add_done_callback runs the callback now if the future is done and has no
executor, else schedules it on the executor as a task (as rclpy does). A Task runs a function
or a coroutine; a coroutine that awaits a Future yields until that future is done, and the
executor resumes it only then (rclpy polls it on every spin; the effect is the same).
"""

from __future__ import annotations

import inspect
import sys
import warnings
import weakref
from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any, Generic, TypeVar

if TYPE_CHECKING:
    from .executors import Executor

T = TypeVar("T")


class Future(Generic[T]):
    """The outcome of a task in the future."""

    def __init__(self, *, executor: Executor | None = None) -> None:
        self._done = False
        self._cancelled = False
        self._result: T | None = None
        self._exception: BaseException | None = None
        self._exception_fetched = False
        self._callbacks: list[Callable[[Future[T]], None]] = []
        self._executor: weakref.ReferenceType[Executor] | None = None
        self._set_executor(executor)

    def __del__(self) -> None:
        if self._exception is not None and not self._exception_fetched:
            print(
                "The following exception was never retrieved: " + str(self._exception),
                file=sys.stderr,
            )

    def __await__(self) -> Generator[Any, None, T | None]:
        while not self._done:
            yield self  # the Task that awaits resumes once this future is done
        return self.result()

    def __repr__(self) -> str:
        state = "cancelled" if self._cancelled else "done" if self._done else "pending"
        return f"<{type(self).__name__} {state}>"

    def cancel(self) -> None:
        if not self._done:
            self._cancelled = True
        self._schedule_or_invoke_done_callbacks()

    def cancelled(self) -> bool:
        return self._cancelled

    def done(self) -> bool:
        return self._done

    def result(self) -> T | None:
        exception = self.exception()
        if exception:
            raise exception
        return self._result

    def exception(self) -> BaseException | None:
        self._exception_fetched = True
        return self._exception

    def set_result(self, result: T) -> None:
        self._result = result
        self._done = True
        self._cancelled = False
        self._schedule_or_invoke_done_callbacks()

    def set_exception(self, exception: BaseException) -> None:
        self._exception = exception
        self._exception_fetched = False
        self._done = True
        self._cancelled = False
        self._schedule_or_invoke_done_callbacks()

    def _executor_now(self) -> Executor | None:
        return self._executor() if self._executor is not None else None

    def _schedule_or_invoke_done_callbacks(self) -> None:
        callbacks, self._callbacks = self._callbacks, []
        executor = self._executor_now()
        if executor is not None:
            for callback in callbacks:
                executor.create_task(callback, self)
            return
        for callback in callbacks:
            try:
                callback(self)
            except Exception as error:
                warnings.warn(f"Unhandled exception in done callback: {error}", stacklevel=2)

    def _set_executor(self, executor: Executor | None) -> None:
        self._executor = None if executor is None else weakref.ref(executor)

    def add_done_callback(self, callback: Callable[[Future[T]], None]) -> None:
        if not self._done:
            self._callbacks.append(callback)
            return
        executor = self._executor_now()
        if executor is not None:
            executor.create_task(callback, self)
        else:
            callback(self)


class Task(Future[T]):
    """Runs a function or a coroutine to completion (made by an executor)."""

    def __init__(
        self,
        handler: Any,
        args: list[Any] | tuple[Any, ...] | None = None,
        kwargs: dict[str, Any] | None = None,
        executor: Executor | None = None,
    ) -> None:
        super().__init__(executor=executor)
        self._handler = handler
        self._args = list(args or [])
        self._kwargs = dict(kwargs or {})
        if inspect.iscoroutinefunction(handler):
            self._handler = handler(*self._args, **self._kwargs)
            self._args, self._kwargs = [], {}
        self._executing = False
        self._awaiting: Future[Any] | None = None

    def ready(self) -> bool:
        """Not done, not running, and not waiting on a future that is still pending."""
        if self._done or self._executing:
            return False
        return self._awaiting is None or self._awaiting.done()

    def __call__(self) -> None:
        if self._done or self._executing:
            return
        self._executing = True
        try:
            if inspect.iscoroutine(self._handler):
                try:
                    awaited = self._handler.send(None)
                except StopIteration as stop:
                    self._handler.close()
                    self.set_result(stop.value)
                    self._complete_task()
                except Exception as error:
                    self.set_exception(error)
                    self._complete_task()
                else:
                    self._awaiting = awaited if isinstance(awaited, Future) else None
            else:
                try:
                    self.set_result(self._handler(*self._args, **self._kwargs))
                except Exception as error:
                    self.set_exception(error)
                self._complete_task()
        finally:
            self._executing = False

    def _complete_task(self) -> None:
        self._handler = None
        self._args, self._kwargs = [], {}

    def executing(self) -> bool:
        return self._executing
