"""One QgsProcessingAlgorithm per module, each a thin adapter around one core function."""
