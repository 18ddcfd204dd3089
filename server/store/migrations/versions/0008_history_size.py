"""issue 33: each saved version's size in bytes, so a workspace's history can be capped and
counted in its student's disk budget without reading every version's text

Revision ID: 0008
Revises: 0007
"""

import sqlalchemy as sa
from alembic import op

revision = "0008"
down_revision = "0007"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("code_versions") as batch:
        batch.add_column(sa.Column("size_bytes", sa.Integer(), nullable=False, server_default="0"))
    # The UTF-8 size of what is already saved (length() counts characters on both).
    if op.get_bind().dialect.name == "postgresql":
        op.execute("UPDATE code_versions SET size_bytes = octet_length(code)")
    else:
        op.execute("UPDATE code_versions SET size_bytes = length(CAST(code AS BLOB))")


def downgrade() -> None:
    with op.batch_alter_table("code_versions") as batch:
        batch.drop_column("size_bytes")
