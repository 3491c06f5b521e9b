"""The comparison report: HTML page and Markdown summary from a results store."""
