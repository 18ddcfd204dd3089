"""The store's one error, apart from the engine: the command line catches it without importing
SQLAlchemy (a third of `robodojo run`'s start-up)."""


class StoreError(RuntimeError):
    """The store cannot be opened or migrated; the message says what to fix."""
