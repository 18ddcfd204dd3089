"""Real robots on the bench: rosserial host for the CrowBot, the iRobot Open Interface for a
Roomba/Create base. Presents the same topics as the simulated robots (server.sim.robots)."""
