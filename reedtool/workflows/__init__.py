"""The workflows every command shares: a model path with its arguments -> robots and
validate's findings -> a vehicle (rotors, mass properties, trim) -> a flight.

Commands sit above this stage and stay thin (options, one call, report, exit code);
`checks/` and `sim/` sit below it as siblings, so what needs both (a hover test refused
on validate's errors, a vehicle flown after its trim) is put together here.
"""
