layout(location = 3) in uint a_record;
uint record_index() { return a_record; }
