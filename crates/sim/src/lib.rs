//! A NeuroTac event-based tactile sensor simulator, evtac's built-in data source.
