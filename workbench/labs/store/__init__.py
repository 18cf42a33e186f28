"""The store: its one connection (SQLite or PostgreSQL), the schema's steps, the
repositories over it, the writes kept while a course database is away, and the students'
workspace files in it."""
