"""The wind as a load in time: the steady wind component and Davenport gusts."""
