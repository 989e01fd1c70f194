//! Building.fmu's shared library: the fmi2* exports of the shared FMI layer for Building's
//! slave (building-model, model/).

fmi2_slave::export_fmi2!(building_model::Building);
