"""Figures, tables and the HTML report. Reporting draws what the experiments computed: it never
fits or simulates, and it returns bytes and text (the CLI writes them through :mod:`hwpts.io`)."""
