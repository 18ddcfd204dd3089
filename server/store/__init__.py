"""The web service's store: SQLAlchemy models (models.py), the engine and migrations (db.py),
and one module of queries per resource. SQLite file by default, PostgreSQL by URL."""
