"""Alembic environment: migrations run on the connection Store.open hands over (no ini file,
no logging setup of Alembic's own: the server's logging stays as it is)."""

from alembic import context

from server.store.models import Base

connection = context.config.attributes["connection"]
context.configure(
    connection=connection,
    target_metadata=Base.metadata,
    render_as_batch=connection.dialect.name == "sqlite",  # SQLite alters tables by copying
)
with context.begin_transaction():
    context.run_migrations()
