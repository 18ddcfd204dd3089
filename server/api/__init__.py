"""The web service: FastAPI routers (one module per resource in routes/), pydantic models at the
edge (schemas.py), authentication (auth.py), and the app that ties them to the store and the run
service (app.py). Thin on purpose: nothing here knows how a run runs."""
